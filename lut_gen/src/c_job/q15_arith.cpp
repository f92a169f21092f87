/// @file q15_arith.cpp
/// @brief The 16-bit format of the generated C job (see q15_arith.hpp).
#include "c_job/q15_arith.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace oneshot::design::cjob {

namespace {

/// The 16-bit format with the most fractional bits holding |v| ≤ range.
QFormat fit16(double range) {
  QFormat f{16, 0};
  int e = 0;
  std::frexp(range, &e);  // range < 2^e
  f.frac = 15 - e;
  while (range > f.max_value()) --f.frac;
  return f;
}

double range_of(const FixedFormats& f, const std::string& name) {
  for (const QuantityFormat& q : f.table)
    if (q.name == name) return q.range;
  throw DesignError("q15 formats: the fixed design has no range for " + name);
}

/// An integer term: C expression (int32 value), fraction, magnitude bound.
struct Raw16 {
  std::string expr;
  int frac = 0;
  double bound = 0;
};

Raw16 product16(const Val& a0, const Val& b0) {
  Val a = a0;
  Val b = b0;
  if (a.count) std::swap(a, b);
  if (a.count || a.fmt.bits != 16 || (!b.count && b.fmt.bits != 16))
    throw std::logic_error("q15: products take 16-bit factors (or a converter code)");
  Raw16 r;
  r.frac = a.fmt.frac + (b.count ? 0 : b.fmt.frac);
  r.bound = bound_of(a) * bound_of(b);
  r.expr = b.count ? "os_m16u(" + a.expr + ", (uint16_t)(" + b.expr + "))" : "os_q15_m(" + a.expr + ", " + b.expr + ")";
  return r;
}

std::string pow2(int k) { return int_literal(static_cast<long long>(1) << k, 32); }

constexpr double kLimit = 2147483647.0;  // 2^31 − 1: every int32 sum stays below it

/// v stored in 16 bits: a cast when |v| ≤ bound < 2^15 − 1, else os_q15_sat (clamp, flag).
std::string store16(const std::string& v, double bound) {
  if (bound <= 32767.0) return "(int16_t)(" + v + ")";
  return "os_q15_sat(" + v + ", sat)";
}

}  // namespace

FixedFormats q15_formats(const FixedFormats& fixed) {
  FixedFormats f = fixed;
  f.table.clear();
  const auto record = [&](const std::string& name, QFormat& slot, double range, const std::string& why) {
    slot = fit16(range);
    f.table.push_back({name, slot, range, why});
  };
  record("state", f.state, range_of(fixed, "state"), "2x the ADC range");
  record("input", f.input, range_of(fixed, "input"), "2x the PWM levels");
  record("code_step", f.code_step, range_of(fixed, "code_step") / 2, "volts per ADC code / PWM step");
  record("inverse_input", f.inverse_input, range_of(fixed, "inverse_input") / 2, "PWM steps per volt");
  record("covariance", f.covariance, range_of(fixed, "covariance") / 128, "2x max(P0, P, R, Q, Qd)");
  record("inverse_covariance", f.inverse_covariance, range_of(fixed, "inverse_covariance") / 2, "1/min(R)");
  f.actuator_steps = QFormat{16, 0};  // unused: the q15 quantisation rounds in one 32-bit product
  for (const QuantityFormat& q : fixed.table)
    if (q.format.bits == 16) f.table.push_back(q);
  return f;
}

void Q15Arith::accumulate(CodeWriter& w, const std::string& dest, Qty out, const std::vector<Term>& terms) const {
  const QFormat o = fmt(out);
  if (terms.empty()) {
    w.line(dest + " = 0;");
    return;
  }
  std::vector<Raw16> raws;
  std::vector<bool> neg;
  for (const Term& t : terms) {
    if (t.kind == Term::Kind::kOne) {
      bool sat = false;
      const long long one = IntegerArith::one_raw(o, sat);
      if (sat) w.line("*sat = 1u;  /* one() does not fit this format */");
      raws.push_back(Raw16{int_literal(one, 16), o.frac, std::fabs(static_cast<double>(one))});
    } else if (t.kind == Term::Kind::kValue) {
      raws.push_back(Raw16{t.a.expr, t.a.count ? 0 : t.a.fmt.frac, bound_of(t.a)});
    } else {
      raws.push_back(product16(t.a, t.b));
    }
    neg.push_back(t.negative);
  }
  if (raws.size() == 1 && terms[0].kind == Term::Kind::kValue && !neg[0] && raws[0].frac == o.frac &&
      !terms[0].a.count && terms[0].a.fmt.bits == 16) {
    w.line(dest + " = " + raws[0].expr + ";");  // a copy (e.g. P C^T with C = [1 0])
    return;
  }
  // The accumulator fraction B: the finest that keeps the worst-case sum below 2^31.
  int top = o.frac;
  for (const Raw16& r : raws) top = std::max(top, r.frac);
  const auto bound_at = [&](int b) {
    double s = b > o.frac ? std::ldexp(1.0, b - o.frac - 1) : 0.0;
    for (const Raw16& r : raws) s += std::ldexp(r.bound, b - r.frac) + (r.frac > b ? 1.0 : 0.0);
    return s;
  };
  int base = top;
  while (bound_at(base) > kLimit) --base;
  const int round = base - o.frac;
  // The rounding half folds into a positive term scaled by exactly 2^round:
  // x 2^r + 2^(r-1) = (2x + 1) 2^(r-1), one constant fewer to build.
  std::size_t folded = raws.size();
  for (std::size_t i = 0; i < raws.size() && round > 0; ++i)
    if (!neg[i] && terms[i].kind != Term::Kind::kProduct && base - raws[i].frac == round) {
      folded = i;
      break;
    }
  std::string sum;
  for (std::size_t i = 0; i < raws.size(); ++i) {
    const int left = base - raws[i].frac;
    std::string e = "(int32_t)" + raws[i].expr;
    if (i == folded) {
      e = "((int32_t)" + raws[i].expr + " * 2 + 1)" + (left > 1 ? " * " + pow2(left - 1) : "");
    } else if (left > 0) {
      e += " * " + pow2(left);
    }
    if (left < 0) e = "(" + e + " >> " + std::to_string(-left) + ")";
    sum += i == 0 ? (neg[i] ? "-" + e : e) : (neg[i] ? " - " : " + ") + e;
  }
  const double bound = bound_at(base);
  if (round > 0) {
    const std::string rounded = folded < raws.size() ? sum : sum + " + " + pow2(round - 1);
    w.line(dest + " = " + store16("(" + rounded + ") >> " + std::to_string(round), std::ldexp(bound, -round) + 1) + ";");
  } else if (round == 0) {
    w.line(dest + " = " + store16(sum, bound) + ";");
  } else {
    throw DesignError("q15: a sum's terms are too large for a 32-bit accumulator at its output's scale");
  }
}

void Q15Arith::mul(CodeWriter& w, const std::string& dest, Qty to, const Val& a, const Val& b) const {
  const QFormat t = fmt(to);
  const Raw16 p = product16(a, b);
  const int shift = p.frac - t.frac;
  std::string value = p.expr;
  double bound = p.bound;
  if (shift > 0) {
    value = "(" + p.expr + " + " + pow2(shift - 1) + ") >> " + std::to_string(shift);
    bound = std::ldexp(p.bound + std::ldexp(1.0, shift - 1), -shift) + 1;
  } else if (shift < 0) {
    if (std::ldexp(p.bound, -shift) > kLimit) throw DesignError("q15: a product does not fit 32 bits at its scale");
    value = p.expr + " * " + pow2(-shift);
    bound = std::ldexp(p.bound, -shift);
  }
  if (p.bound + std::ldexp(1.0, std::max(shift - 1, 0)) > kLimit) throw DesignError("q15: a rounded product overflows");
  w.line(dest + " = " + store16(value, bound) + ";");
}

std::string Q15Arith::slot_to(Qty q, const std::string& raw, int frac, int raw_bits) const {
  if (raw_bits != 16) throw std::logic_error("q15: table slots are 16-bit");
  const QFormat t = fmt(q);
  const int shift = frac - t.frac;
  if (shift == 0) return raw;
  if (shift == 1) return store16("((int32_t)(" + raw + ") + 1) >> 1", 16384.0);
  if (shift > 1 && shift < 31) return store16("(((int32_t)(" + raw + ") >> " + std::to_string(shift - 1) + ") + 1) >> 1",
                                              std::ldexp(32768.0, -shift) + 1);
  if (shift >= 31) return "0";
  if (shift <= -16) throw DesignError("q15: a table slot is too coarse for its quantity's format");
  return store16("(int32_t)(" + raw + ") * " + pow2(-shift), std::ldexp(32768.0, -shift));
}

}  // namespace oneshot::design::cjob
