/// @file float_arith.cpp
/// @brief The float arithmetic of the generated C job (FloatArith, see c_arith.hpp): IEEE
///        single precision written as the C++ core's floating Accumulator computes it, and the
///        integer helpers (comparisons, exact conversions, the Cortex-M0 multiply) whose
///        results are those of the float operations they replace.
#include "c_job/c_arith.hpp"

#include <string>
#include <vector>

namespace oneshot::design::cjob {

namespace {
// A count in [0, 65535] converts exactly; os_f32_of_u16 does it in integers (no __aeabi_ui2f).
std::string float_operand(const Val& v) { return v.count ? "os_f32_of_u16((uint32_t)(" + v.expr + "))" : v.expr; }
}  // namespace

void FloatArith::emit_fmul(CodeWriter& w) {
  w.line("/* a * b in integers (a Cortex-M0 has no 32x32->64 multiply; libgcc's multiplication costs");
  w.line("   about 115 instructions there): the 48-bit product of the 24-bit significands from four");
  w.line("   16x16->32 products, rounded to nearest, ties to even. IEEE rounding is unique, so the");
  w.line("   result is a * b bit for bit; zeros,");
  w.line("   subnormals, infinities, NaNs and results outside the normal range take a * b itself. */");
  w.open("static float os_fmul(float a, float b) {")
      .line("const uint32_t ua = os_f32_bits(a);")
      .line("const uint32_t ub = os_f32_bits(b);")
      .line("const int32_t eb = (int32_t)((ub >> 23) & UINT32_C(0xFF));")
      .line("int32_t e = (int32_t)((ua >> 23) & UINT32_C(0xFF));")
      .line("uint32_t ah, bh, al, bl, t, hi, low, m;")
      .open("if ((uint32_t)(e - 1) >= UINT32_C(0xFE) || (uint32_t)(eb - 1) >= UINT32_C(0xFE)) {")
      .line("return a * b;")
      .close()
      .line("e += eb - 127;")
      .line("/* Significands a = ah 2^8 + al (ah 16 bits with the leading one, al 8 bits), same for b:")
      .line("   a b = (ah bh) 2^16 + (ah bl + al bh) 2^8 + al bl = hi 2^16 + 16 bits whose only use is")
      .line("   whether one is set (low). */")
      .line("ah = ((ua >> 8) & UINT32_C(0x7FFF)) | UINT32_C(0x8000);")
      .line("bh = ((ub >> 8) & UINT32_C(0x7FFF)) | UINT32_C(0x8000);")
      .line("al = ua & UINT32_C(0xFF);")
      .line("bl = ub & UINT32_C(0xFF);")
      .line("low = al * bl;")
      .line("t = ah * bl + al * bh + (low >> 8);  /* < 2^25 */")
      .line("hi = ah * bh + (t >> 8);  /* in [2^30, 2^32) */")
      .line("low = (low | t) & UINT32_C(0xFF);")
      .line("/* Keep 24 bits (m), the next one (t: half an ulp) and whether any below is set (low). */")
      .open("if (hi >= UINT32_C(0x80000000)) {")
      .line("low |= hi & UINT32_C(0x7F);")
      .line("t = hi & UINT32_C(0x80);")
      .line("m = hi >> 8;")
      .line("++e;")
      .middle("} else {")
      .line("low |= hi & UINT32_C(0x3F);")
      .line("t = hi & UINT32_C(0x40);")
      .line("m = hi >> 7;")
      .close()
      .open("if ((uint32_t)(e - 1) >= UINT32_C(0xFE)) {")
      .line("return a * b;  /* subnormal or overflowing: the library rounds */")
      .close()
      .open("if (t != 0u && (low != 0u || (m & 1u) != 0u)) {  /* to nearest, ties to even */")
      .line("++m;")
      .open("if (m == UINT32_C(0x1000000)) {")
      .line("m >>= 1;")
      .open("if (++e > 254) {").line("return a * b;").close()
      .close()
      .close()
      .line("return os_f32_of_bits(((ua ^ ub) & UINT32_C(0x80000000)) | ((uint32_t)e << 23) | (m & UINT32_C(0x7FFFFF)));")
      .close();
}

void FloatArith::emit_helpers(CodeWriter& w) {
  w.line("/* ONESHOT_JOB_INTEGER_FLOAT (default on a Cortex-M0): comparisons, exact conversions and the");
  w.line("   multiplication in integers on the IEEE single bits, each with the result of the float");
  w.line("   operation it replaces; elsewhere (FPU, or a library in assembly as on AVR) the plain C. */");
  w.line("#if !defined(ONESHOT_JOB_INTEGER_FLOAT) && defined(__ARM_ARCH_6M__)");
  w.line("#define ONESHOT_JOB_INTEGER_FLOAT 1");
  w.line("#endif");
  w.line("#if defined(ONESHOT_JOB_INTEGER_FLOAT) && ONESHOT_JOB_INTEGER_FLOAT");
  w.line("/* The bits of v and back (C99 union punning). */");
  w.open("static inline uint32_t os_f32_bits(float v) {")
      .line("union { float f; uint32_t u; } x;")
      .line("x.f = v;")
      .line("return x.u;")
      .close();
  w.open("static inline float os_f32_of_bits(uint32_t u) {")
      .line("union { float f; uint32_t u; } x;")
      .line("x.u = u;")
      .line("return x.f;")
      .close();
  w.line("/* 0 < v: bits 1 .. 0x7F800000 (+subnormal .. +inf); false for +-0, negatives and NaN. */");
  w.open("static inline int os_f32_positive(float v) {")
      .line("return os_f32_bits(v) - 1u < UINT32_C(0x7F800000);")
      .close();
  w.line("/* v < top for v in +0 .. +inf and top > 0 (top_bits its bits): non-negative floats order as");
  w.line("   their bits. */");
  w.open("static inline int os_f32_below(float v, uint32_t top_bits, float top) {")
      .line("(void)top;")
      .line("return os_f32_bits(v) < top_bits;")
      .close();
  w.line("/* (float)v for 0 <= v < 2^16, exact: the leading one at bit p gives the exponent 127 + p. */");
  w.open("static inline float os_f32_of_u16(uint32_t v) {")
      .line("uint32_t p = 0u;")
      .open("if (v == 0u) {").line("return " + float_literal(0.0F) + ";").close()
      .open("if (v >= UINT32_C(0x100)) {").line("p = 8u;").close()
      .open("if ((v >> p) >= UINT32_C(0x10)) {").line("p += 4u;").close()
      .open("if ((v >> p) >= UINT32_C(0x4)) {").line("p += 2u;").close()
      .open("if ((v >> p) >= UINT32_C(0x2)) {").line("p += 1u;").close()
      .line("return os_f32_of_bits(((UINT32_C(127) + p) << 23) | ((v << (23u - p)) & UINT32_C(0x7FFFFF)));")
      .close();
  w.line("/* (int32_t)v, truncation, for +0 <= v < 2^23 (no __aeabi_f2iz). */");
  w.open("static inline int32_t os_f32_trunc(float v) {")
      .line("const uint32_t b = os_f32_bits(v);")
      .open("if (b < UINT32_C(0x3F800000)) {").line("return 0;").close()
      .line("return (int32_t)(((b & UINT32_C(0x7FFFFF)) | UINT32_C(0x800000)) >> (150u - (b >> 23)));")
      .close();
  emit_fmul(w);
  w.line("#else");
  w.open("static inline int os_f32_positive(float v) {").line("return " + float_literal(0.0F) + " < v;").close();
  w.open("static inline int os_f32_below(float v, uint32_t top_bits, float top) {")
      .line("(void)top_bits;")
      .line("return v < top;")
      .close();
  w.open("static inline float os_f32_of_u16(uint32_t v) {").line("return (float)v;").close();
  w.open("static inline int32_t os_f32_trunc(float v) {").line("return (int32_t)v;").close();
  w.open("static inline float os_fmul(float a, float b) {").line("return a * b;").close();
  w.line("#endif");
}

void FloatArith::accumulate(CodeWriter& w, const std::string& dest, Qty, const std::vector<Term>& terms) const {
  if (terms.empty()) {
    w.line(dest + " = " + zero(Qty::kState) + ";");
    return;
  }
  std::string sum;
  for (std::size_t i = 0; i < terms.size(); ++i) {
    const Term& t = terms[i];
    std::string e;
    if (t.kind == Term::Kind::kOne) {
      e = float_literal(1.0F);
    } else if (t.kind == Term::Kind::kValue) {
      e = float_operand(t.a);
    } else {
      e = "os_fmul(" + float_operand(t.a) + ", " + float_operand(t.b) + ")";
    }
    if (i == 0) {
      sum = t.negative ? "-" + e : e;  // the empty accumulator takes ±the first term
    } else {
      sum = "(" + sum + (t.negative ? " - " : " + ") + e + ")";
    }
  }
  w.line(dest + " = " + sum + ";");
}

void FloatArith::mul(CodeWriter& w, const std::string& dest, Qty, const Val& a, const Val& b) const {
  w.line(dest + " = os_fmul(" + float_operand(a) + ", " + float_operand(b) + ");");
}

Val FloatArith::constant(Qty, double v, const std::string&) const {
  return Val::of(float_literal(static_cast<float>(v)), QFormat{32, 0});
}

}  // namespace oneshot::design::cjob
