/// @file c_arith.cpp
/// @brief Fixed-point arithmetic of the generated C job (see c_arith.hpp; float: float_arith.cpp).
#include "c_job/c_arith.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace oneshot::design::cjob {

void add_value(std::vector<Term>& terms, bool negative, const Val& x) {
  if (x.is_zero()) return;
  if (x.is_one()) {
    terms.push_back(Term{Term::Kind::kOne, negative, {}, {}});
    return;
  }
  terms.push_back(Term{Term::Kind::kValue, negative, x, {}});
}

void add_term(std::vector<Term>& terms, bool negative, const Val& a, const Val& b) {
  if (a.is_zero() || b.is_zero()) return;
  if (a.is_one() && b.is_one()) {
    terms.push_back(Term{Term::Kind::kOne, negative, {}, {}});
  } else if (a.is_one()) {
    terms.push_back(Term{Term::Kind::kValue, negative, b, {}});
  } else if (b.is_one()) {
    terms.push_back(Term{Term::Kind::kValue, negative, a, {}});
  } else {
    terms.push_back(Term{Term::Kind::kProduct, negative, a, b});
  }
}

// ---------------------------------------------------------------------------------------
// Fixed point.

QFormat format_of(const FixedFormats& f, Qty q) {
  switch (q) {
    case Qty::kTransition: return f.transition;
    case Qty::kInputGain: return f.input_gain;
    case Qty::kCovariance: return f.covariance;
    case Qty::kInverseCovariance: return f.inverse_covariance;
    case Qty::kState: return f.state;
    case Qty::kInput: return f.input;
    case Qty::kInverseInput: return f.inverse_input;
    case Qty::kActuatorSteps: return f.actuator_steps;
    case Qty::kCodeStep: return f.code_step;
    case Qty::kKalmanGain: return f.kalman_gain;
    case Qty::kFeedbackGain: return f.feedback_gain;
    case Qty::kFraction: return f.fraction;
  }
  throw std::logic_error("unknown quantity");
}

QFormat IntegerArith::fmt(Qty q) const { return format_of(f_, q); }

long long IntegerArith::one_raw(QFormat f, bool& saturates) {
  // As ScalarTraits<Fixed>::from_double(1.0).
  const double r = std::ldexp(1.0, f.frac) + 0.5;
  const double max = std::ldexp(1.0, f.bits - 1) - 1;
  const double min = -std::ldexp(1.0, f.bits - 1);
  saturates = false;
  if (r >= max) {
    saturates = r >= max + 1.0;
    return static_cast<long long>(max);
  }
  if (r <= min) {
    saturates = r <= min - 1.0;
    return static_cast<long long>(min);
  }
  return static_cast<long long>(r);
}

std::string IntegerArith::one(Qty q, bool& saturates) const { return int_literal(one_raw(fmt(q), saturates), fmt(q).bits); }

Val IntegerArith::constant(Qty q, double v, const std::string& what) const {
  const QFormat f = fmt(q);
  return Val::of(int_literal(f.raw_of(v, what), f.bits), f);
}

namespace {

/// An integer term of a fixed sum: its C expression, scale, width and magnitude bound.
struct Raw {
  std::string expr;  // C expression, int32_t or int64_t
  bool wide = false; // int64_t expression
  int frac = 0;      // value = expr · 2^−frac
  double bound = 0;  // |expr| ≤ bound
};

std::string as16(const Val& v) { return v.fmt.bits == 16 ? v.expr : "(int16_t)(" + v.expr + ")"; }

/// The exact product a·b (detail::wide_product), as cheaply as the widths allow.
Raw product(const Val& a0, const Val& b0) {
  Val a = a0;
  Val b = b0;
  // Order: wider / signed factor first.
  if (a.count || (a.fmt.bits < b.fmt.bits && !b.count)) std::swap(a, b);
  Raw r;
  r.frac = a.fmt.frac + b.fmt.frac;
  r.bound = bound_of(a) * bound_of(b);
  if (a.count) {  // two counts: an ordinary 32-bit product of small values
    r.expr = "((int32_t)(" + a.expr + ") * (int32_t)(" + b.expr + "))";
  } else if (a.fmt.bits == 16 && b.count) {
    r.expr = "os_m16u(" + a.expr + ", (uint16_t)(" + b.expr + "))";
  } else if (a.fmt.bits == 16) {
    r.expr = "os_m16(" + a.expr + ", " + b.expr + ")";
  } else if (b.count) {
    r.expr = "os_m32xu16(" + a.expr + ", (uint16_t)(" + b.expr + "))";
    r.wide = true;
  } else if (b.fmt.bits == 16) {
    r.expr = "os_m32x16(" + a.expr + ", " + as16(b) + ")";
    r.wide = true;
  } else {
    r.expr = "os_m32x32(" + a.expr + ", " + b.expr + ")";
    r.wide = true;
  }
  return r;
}

std::string pow2(int k, bool wide) { return int_literal(static_cast<long long>(1) << k, wide ? 64 : 32); }

/// Saturation of an expression of the given width into `bits`, or the plain cast when
/// `bound` proves it fits.
std::string saturate(const std::string& e, bool wide, int bits, double bound) {
  if (bound < std::ldexp(1.0, bits - 1) - 1) return bits == 16 ? "(int16_t)(" + e + ")" : "(int32_t)(" + e + ")";
  if (bits == 32) return wide ? "os_sat32(" + e + ", sat)" : e;
  return wide ? "os_sat16_64(" + e + ", sat)" : "os_sat16(" + e + ", sat)";
}

}  // namespace

void FixedArith::accumulate(CodeWriter& w, const std::string& dest, Qty out, const std::vector<Term>& terms) const {
  const QFormat o = fmt(out);
  if (terms.empty()) {
    w.line(dest + " = 0;");
    return;
  }
  constexpr int kGuard = 16;  // Accumulator<Fixed>::kGuard
  const int acc_frac = o.frac + kGuard;
  std::vector<Raw> raws;
  std::vector<bool> neg;
  for (const Term& t : terms) {
    Raw r;
    if (t.kind == Term::Kind::kOne) {
      bool sat = false;
      const long long one = one_raw(o, sat);
      if (sat) w.line("*sat = 1u;  /* one() does not fit this format */");
      r = Raw{int_literal(one, o.bits), false, o.frac, std::fabs(static_cast<double>(one))};
    } else if (t.kind == Term::Kind::kValue) {
      r = Raw{t.a.expr, false, t.a.count ? 0 : t.a.fmt.frac, bound_of(t.a)};
    } else {
      r = product(t.a, t.b);
    }
    raws.push_back(r);
    neg.push_back(t.negative);
  }
  // Terms finer than the register are floored (floor_shift); exact terms share a common
  // power of two, factored out so that no shift is spent on the guard bits.
  bool all_exact = true;
  int common = std::numeric_limits<int>::max();
  for (const Raw& r : raws) {
    const int shift = r.frac - acc_frac;
    all_exact = all_exact && shift <= 0;
    common = std::min(common, -shift);
  }
  const int base = all_exact ? acc_frac - common : acc_frac;
  const int round = all_exact ? kGuard - common : kGuard;
  double bound = round > 0 ? std::ldexp(1.0, round - 1) : 0.0;
  bool any_wide = false;
  for (const Raw& r : raws) {
    bound += std::ldexp(r.bound, base - r.frac);
    any_wide = any_wide || r.wide;
  }
  if (raws.size() == 1 && terms[0].kind != Term::Kind::kProduct && !neg[0] && base == raws[0].frac && round == 0) {
    // A copy (e.g. P C^T with C = [1 0]): exact, saturating only into a narrower format.
    const int bits = terms[0].kind == Term::Kind::kOne ? o.bits : (terms[0].a.count ? 32 : terms[0].a.fmt.bits);
    w.line(dest + " = " + (bits <= o.bits ? raws[0].expr : saturate(raws[0].expr, false, o.bits, raws[0].bound)) + ";");
    return;
  }
  const bool wide = any_wide || bound >= std::ldexp(1.0, 31) || round < 0;
  const std::string cast = wide ? "(int64_t)" : "(int32_t)";
  std::string sum;
  for (std::size_t i = 0; i < raws.size(); ++i) {
    const Raw& r = raws[i];
    const int left = base - r.frac;
    std::string e = cast + r.expr;
    if (left > 0) e = e + " * " + pow2(left, wide);
    if (left < 0) e = "(" + e + " >> " + std::to_string(-left) + ")";
    if (i == 0) {
      sum = neg[i] ? "-" + e : e;
    } else {
      sum += (neg[i] ? " - " : " + ") + e;
    }
  }
  std::string value;
  double out_bound = bound;
  if (round > 0) {
    value = "(" + sum + " + " + pow2(round - 1, wide) + ") >> " + std::to_string(round);
    out_bound = std::ldexp(bound, -round) + 1;
  } else if (round < 0) {
    value = "(" + sum + ") * " + pow2(-round, true);
    out_bound = std::ldexp(bound, -round);
  } else {
    value = sum;
  }
  w.line(dest + " = " + saturate(value, wide, o.bits, out_bound) + ";");
}

void FixedArith::mul(CodeWriter& w, const std::string& dest, Qty to, const Val& a, const Val& b) const {
  const QFormat t = fmt(to);
  Raw p = product(a, b);
  const int shift = p.frac - t.frac;
  double bound = shift > 0 ? p.bound + std::ldexp(1.0, shift - 1) : std::ldexp(p.bound, -shift);
  const bool wide = p.wide || bound >= std::ldexp(1.0, 31);
  const std::string e = (wide && !p.wide ? "(int64_t)" : "") + p.expr;
  std::string value = e;
  if (shift > 0) {
    value = "(" + e + " + " + pow2(shift - 1, wide) + ") >> " + std::to_string(shift);
    bound = std::ldexp(bound, -shift) + 1;
  } else if (shift < 0) {
    value = e + " * " + pow2(-shift, wide);
  }
  w.line(dest + " = " + saturate(value, wide, t.bits, bound) + ";");
}

std::string FixedArith::slot_to(Qty q, const std::string& raw, int frac, int raw_bits) const {
  const QFormat t = fmt(q);
  const int shift = frac - t.frac;
  std::string e;
  bool wide = false;
  double bound = std::ldexp(1.0, raw_bits - 1);
  if (shift == 0) {
    e = "(int32_t)(" + raw + ")";
  } else if (shift == 1 && raw_bits == 32) {
    // round_shift32(v, 1) = (v + 1) >> 1, in 64 bits so that v = INT32_MAX cannot overflow.
    e = "(((int64_t)(" + raw + ") + 1) >> 1)";
    wide = true;
    bound = bound / 2 + 1;
  } else if (shift == 1) {
    e = "(((int32_t)(" + raw + ") + 1) >> 1)";
    bound = bound / 2 + 1;
  } else if (shift > 1 && shift < 32) {
    e = "((((int32_t)(" + raw + ") >> " + std::to_string(shift - 1) + ") + 1) >> 1)";  // round_shift32
    bound = std::ldexp(bound, -shift) + 1;
  } else if (shift < 0) {
    e = "((int64_t)(" + raw + ") * " + pow2(-shift, true) + ")";
    wide = true;
    bound = std::ldexp(bound, -shift);
  } else {
    e = "(((int64_t)(" + raw + ") + " + pow2(shift - 1, true) + ") >> " + std::to_string(shift) + ")";
    wide = true;
    bound = 1;
  }
  if (t.bits == 32 && !wide) return e;
  return saturate(e, wide, t.bits, bound);
}

namespace {
/// static inline int<out>_t name(int<in>_t v, uint8_t *sat): v clamped to int<out>_t, the
/// sticky flag raised when it was out of range (detail::saturate).
void emit_clamp(CodeWriter& w, const std::string& name, int out_bits, int in_bits) {
  const std::string out = std::to_string(out_bits);
  const std::string in = "int" + std::to_string(in_bits) + "_t";
  w.open("static inline int" + out + "_t " + name + "(" + in + " v, uint8_t *sat) {")
      .open("if (v > (" + in + ")INT" + out + "_MAX) {").line("*sat = 1u;").line("return INT" + out + "_MAX;").close()
      .open("if (v < (" + in + ")INT" + out + "_MIN) {").line("*sat = 1u;").line("return INT" + out + "_MIN;").close()
      .line("return (int" + out + "_t)v;")
      .close();
}
}  // namespace

void FixedArith::emit_helpers(CodeWriter& w) {
  w.line("/* Exact products (detail::wide_product): 16x16->32 multiplies only, so that 16-bit");
  w.line("   targets use their native multiplier and ARMv6-M needs no 64-bit multiply routine. */");
  w.open("static inline int32_t os_m16(int16_t a, int16_t b) {").line("return (int32_t)a * (int32_t)b;").close();
  w.line("/* |a * b| < 2^31 for a signed 16-bit a and b in [0, 65535]. */");
  w.open("static inline int32_t os_m16u(int16_t a, uint16_t b) {").line("return (int32_t)a * (int32_t)b;").close();
  w.open("static inline int64_t os_m32x16(int32_t a, int16_t b) {")
      .line("const int32_t hi = (int32_t)(int16_t)(a >> 16) * (int32_t)b;")
      .line("const int32_t lo = (int32_t)(uint16_t)((uint32_t)a & UINT32_C(0xFFFF)) * (int32_t)b;")
      .line("return (int64_t)hi * INT64_C(65536) + (int64_t)lo;")
      .close();
  w.open("static inline int64_t os_m32xu16(int32_t a, uint16_t b) {")
      .line("const int32_t hi = (int32_t)(int16_t)(a >> 16) * (int32_t)b;")
      .line("const uint32_t lo = (uint32_t)(uint16_t)((uint32_t)a & UINT32_C(0xFFFF)) * (uint32_t)b;")
      .line("return (int64_t)hi * INT64_C(65536) + (int64_t)lo;")
      .close();
  w.open("static inline int64_t os_m32x32(int32_t a, int32_t b) {")
      .line("const int32_t ah = (int32_t)(int16_t)(a >> 16);")
      .line("const int32_t bh = (int32_t)(int16_t)(b >> 16);")
      .line("const uint32_t al = (uint32_t)a & UINT32_C(0xFFFF);")
      .line("const uint32_t bl = (uint32_t)b & UINT32_C(0xFFFF);")
      .line("const int64_t middle = (int64_t)(ah * (int32_t)bl) + (int64_t)((int32_t)al * bh);")
      .line("return (int64_t)(ah * bh) * INT64_C(4294967296) + middle * INT64_C(65536) + (int64_t)(al * bl);")
      .close();
  w.line("/* Saturation (detail::saturate): clamps and raises the sticky flag. */");
  emit_clamp(w, "os_sat32", 32, 64);
  emit_clamp(w, "os_sat16", 16, 32);
  w.line("/* 16x16->32 product of the q15 variants: operands in 16-bit range held in int_fast16_t (a");
  w.line("   register-width int on 32-bit cores, int16_t on 16- and 8-bit ones). */");
  w.open("static inline int32_t os_q15_m(int_fast16_t a, int_fast16_t b) {").line("return (int32_t)a * (int32_t)b;").close();
  w.line("/* 16-bit store of a 32-bit sum (q15 variants): one sign extension and one compare; out of");
  w.line("   range it clamps and raises the sticky flag (narrowing is modulo: checked at compile time). */");
  w.open("static inline int16_t os_q15_sat(int32_t v, uint8_t *sat) {")
      .line("const int16_t t = (int16_t)v;")
      .open("if ((int32_t)t != v) {").line("*sat = 1u;").line("return v > 0 ? INT16_MAX : INT16_MIN;").close()
      .line("return t;")
      .close();
  emit_clamp(w, "os_sat16_64", 16, 64);
}

void FixedArith::emit_division_helpers(CodeWriter& w) {
  w.line("/* Bit length of v > 0 (no CLZ instruction on ARMv6-M, none in C99). */");
  w.open("static inline int16_t os_bitlen(uint32_t v) {")
      .line("int16_t n = 1;")
      .open("if (v >= UINT32_C(0x10000)) {").line("v >>= 16;").line("n += 16;").close()
      .open("if (v >= UINT32_C(0x100)) {").line("v >>= 8;").line("n += 8;").close()
      .open("if (v >= UINT32_C(0x10)) {").line("v >>= 4;").line("n += 4;").close()
      .open("if (v >= UINT32_C(4)) {").line("v >>= 2;").line("n += 2;").close()
      .open("if (v >= UINT32_C(2)) {").line("n += 1;").close()
      .line("return n;")
      .close();
  std::string seeds;
  for (int i = 0; i < 16; ++i) {
    seeds += (i ? ", " : "") + std::to_string(std::lround(std::ldexp(1.0, 20) / (i + 16.5)));
  }
  w.line("/* floor((2^31 + floor(m/2)) / m) for 2^15 <= m < 2^16 (the division of reciprocal<>), without a");
  w.line("   division: a 16-entry seed of 2^31/m, two Newton steps y += y (2^31 - m y) / 2^31 in 32-bit");
  w.line("   arithmetic, then the remainder n - y m (|.| < 2^31, read through its sign bit) is brought");
  w.line("   into [0, m), which makes the quotient exact whatever the estimate. */");
  w.line("static ONESHOT_CONST_TABLE const uint16_t os_recip_seed[16] = {" + seeds + "};");
  w.open("static inline uint32_t os_div31(uint32_t m) {")
      .line("const uint32_t n = UINT32_C(0x80000000) + (m >> 1);")
      .line("uint32_t y = os_recip_seed[(m >> 11) - 16u];")
      .line("uint32_t t = m * y;")
      .open("if (t <= UINT32_C(0x80000000)) {").line("y += (y * ((UINT32_C(0x80000000) - t) >> 12)) >> 19;")
      .middle("} else {").line("y -= (y * ((t - UINT32_C(0x80000000)) >> 12)) >> 19;").close()
      .line("t = m * y;")
      .open("if (t <= UINT32_C(0x80000000)) {").line("y += (y * ((UINT32_C(0x80000000) - t) >> 8)) >> 23;")
      .middle("} else {").line("y -= (y * ((t - UINT32_C(0x80000000)) >> 8)) >> 23;").close()
      .line("t = n - y * m;")
      .open("while (t >= UINT32_C(0x80000000)) {").line("--y;").line("t += m;").close()
      .open("while (t >= m) {").line("++y;").line("t -= m;").close()
      .line("return y;")
      .close();
}

}  // namespace oneshot::design::cjob
