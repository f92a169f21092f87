/// @file c_job_q15.cpp
/// @brief The q15 variants' own pieces. Discretization: one table row per grid interval holding
///        each free entry of Φ, Γ, Q_d as a polynomial in r = (τ − k·g)/g (q15_poly_table.hpp),
///        evaluated by Horner in 16×16→32 steps and rounded once into the filter's formats; one
///        prediction per interval of τ (whole table ranges first when τ is beyond it), so no
///        16-bit composition of two intervals is ever needed. Reciprocal: 1/S from a 16-bit S by
///        a seed table, two Newton steps and a one-step remainder correction, in 32 bits.
#include <algorithm>
#include <cmath>

#include "c_job/c_job_variant.hpp"
#include "c_job/q15_poly_table.hpp"

namespace oneshot::design::cjob {

namespace {
std::string pow2_literal(int k) { return int_literal(static_cast<long long>(1) << k, 32); }
}  // namespace

void VariantEmitter::emit_q15_table(CodeWriter& w) {
  q15_table_ = std::make_shared<Q15PolyTable>(design_q15_poly_table(plant_, design_, ar(), spec_.table.granularity_us,
                                                                    spec_.table.range_us, free_members(), !spec_.exact_subgrid));
  const Q15PolyTable& t = *q15_table_;
  const std::int32_t g = spec_.table.granularity_us;
  std::string layout;
  for (const Q15Slot& s : t.slots) {
    std::string names;
    for (std::size_t m : s.members)
      names += (names.empty() ? "" : "=") + t.members[m].member + "(" + std::to_string(t.members[m].i) + "," +
               std::to_string(t.members[m].j) + ")";
    char err[32];
    std::snprintf(err, sizeof err, "%.3f", s.max_error_lsb);
    layout += " " + names + ": degree " + std::to_string(s.degree) + ", 2^-" + std::to_string(s.frac) + ", fit error " +
              err + " LSB;";
  }
  w.line("/* Per " + std::to_string(g) + " us interval k (tau = k g + r g): each free entry of Phi, Gamma, Q_d as a");
  w.line("   polynomial in r, c_0 + c_1 r + ..., c_0 its exact value at k g (fitted to the exact");
  w.line("   discretization, error below 1/4 LSB of its format):" + layout + " */");
  w.open("static ONESHOT_CONST_TABLE const int16_t " + fn("poly") + "[" + std::to_string(t.rows.size()) + "][" +
         std::to_string(std::max<std::size_t>(t.width, 1)) + "] = {");
  for (std::size_t k = 0; k < t.rows.size(); ++k) {
    std::string row = "{";
    for (std::size_t j = 0; j < t.rows[k].size(); ++j) row += (j ? ", " : "") + int_literal(t.rows[k][j], 16);
    if (t.rows[k].empty()) row += "0";
    w.line(row + (k + 1 < t.rows.size() ? "}," : "}"));
  }
  w.close("};");
}

void VariantEmitter::emit_q15_interval(CodeWriter& w) const {
  const Q15PolyTable& t = *q15_table_;
  const std::string tab = fn("poly") + "[k][";
  const bool poly = spec_.exact_subgrid;
  w.line("/* d = Phi, Gamma, Q_d over k g + r g (r in Q15): Horner, the last step kept in 32 bits and");
  w.line("   rounded half up straight into each entry's format. */");
  w.open("static void " + fn("interval") + "(uint8_t k, " + (poly ? "int_fast16_t r, " : "") + triple_type() +
         " *d, uint8_t *sat) {");
  w.line("(void)sat;");
  for (std::size_t si = 0; si < t.slots.size(); ++si) {
    const Q15Slot& s = t.slots[si];
    const std::string o = std::to_string(s.offset);
    std::string expr;
    int frac = s.frac;
    double bound = 0;
    for (const auto& row : t.rows) {
      double sum = 0;
      for (int j = 0; j <= s.degree; ++j) sum += std::fabs(static_cast<double>(row[s.offset + static_cast<std::size_t>(j)]));
      bound = std::max(bound, sum + s.degree);
    }
    if (s.degree == 0) {
      expr = "(int32_t)" + tab + o + "]";
    } else {
      const std::string v = "v" + std::to_string(si);
      w.line("int_fast16_t " + v + " = " + tab + std::to_string(s.offset + static_cast<std::size_t>(s.degree)) + "];");
      for (int j = s.degree - 1; j >= 1; --j)
        w.line(v + " = (int_fast16_t)(((os_q15_m(" + v + ", r) + 16384) >> 15) + " + tab +
               std::to_string(s.offset + static_cast<std::size_t>(j)) + "]);");
      w.line("const int32_t w" + std::to_string(si) + " = os_q15_m(" + v + ", r) + (int32_t)" + tab + o + "] * 32768;");
      expr = "w" + std::to_string(si);
      frac += 15;
      bound *= 32768.0;
    }
    for (std::size_t m : s.members) {
      const Q15Member& mem = t.members[m];
      const int sh = frac - ar().fmt(mem.q).frac;
      const std::string dest = "d->" + mem.member + "[" + std::to_string(mem.index) + "]";
      std::string value = expr;
      double out = bound;
      if (sh > 0) {
        value = "(" + expr + " + " + pow2_literal(sh - 1) + ") >> " + std::to_string(sh);
        out = std::ldexp(bound, -sh) + 1;
      } else if (sh < 0) {
        if (std::ldexp(bound, -sh) > 2147483647.0) throw DesignError("C job q15: a table slot is far coarser than its format");
        value = expr + " * " + pow2_literal(-sh);
        out = std::ldexp(bound, -sh);
      }
      w.line(dest + " = " + (out <= 32767.0 ? "(int16_t)(" + value + ")" : "os_q15_sat(" + value + ", sat)") + ";");
    }
  }
  w.close();
}

void VariantEmitter::emit_q15_advance(CodeWriter& w) {
  const TableText& t = spec_.table;
  const std::int32_t g = t.granularity_us;
  const std::string range = int_literal(t.range_us, 32);
  const auto last = static_cast<std::uint32_t>(t.range_us / g);
  const auto max_arg = static_cast<std::uint32_t>(plant_.period_us + tau_bound_us());
  const bool poly = spec_.exact_subgrid;
  const std::string r0 = poly ? "0, " : "";
  w.line("/* Predict over tau_us (TableDiscretizer::discretize's intervals, OutOfRange::kExtend): tau < 0");
  w.line("   clamps to 0; beyond the range, whole ranges (up to 4) then the remainder, one prediction each");
  w.line("   (Phi(a+b) = Phi(b) Phi(a) with the input held: predicting over a then b is predicting over a+b). */");
  w.open("static uint8_t " + fn("advance") + "(" + state_type() + " *s, int32_t tau_us, uint8_t *sat) {");
  w.line(triple_type() + " d;");
  w.line("uint8_t status = ONESHOT_JOB_STATUS_OK;");
  w.line("int32_t index;");
  w.open("if (tau_us < 0) {").line("tau_us = 0;").line("status = ONESHOT_JOB_STATUS_CLAMPED;").close();
  w.open("if (tau_us > " + range + ") {");
  emit_range_split(w, "int32_t ", static_cast<std::uint32_t>(t.range_us), max_arg, divisions_);
  w.line(fn("interval") + "((uint8_t)" + std::to_string(last) + "u, " + r0 + "&d, sat);  /* the whole range */");
  w.open("for (; repeats > 0; --repeats) {").line(fn("predict") + "(s, &d, sat);").close();
  w.line("tau_us = remainder;");
  w.close();
  w.open("if (tau_us == 0) {").line("return status;").close();
  w.line("index = " + divide_by_constant("tau_us", static_cast<std::uint32_t>(g), static_cast<std::uint32_t>(t.range_us), divisions_) + ";");
  if (poly) {
    const int f = ar().fmt(Qty::kFraction).frac;
    if (f != 15) throw DesignError("C job q15: the sub-grid fraction must be Q15");
    const auto scale = static_cast<std::uint32_t>(((std::uint64_t{1} << 31) + static_cast<std::uint64_t>(g) / 2) /
                                                  static_cast<std::uint64_t>(g));
    w.open("{");
    w.line("/* r = (tau - k g)/g in Q15: one 32-bit multiply by 2^31/g (tau - k g < g: r < 2^15). */");
    w.line("const int_fast16_t r = (int_fast16_t)(((uint32_t)(tau_us - index * " + int_literal(g, 32) + ") * " +
           u32_literal(scale) + " + UINT32_C(0x8000)) >> 16);");
    w.line(fn("interval") + "((uint8_t)index, r, &d, sat);");
    w.close();
  } else {
    w.line("/* tau_us is a multiple of g here (the job rounds tau to the grid first). */");
    w.line(fn("interval") + "((uint8_t)index, &d, sat);");
  }
  w.line(fn("predict") + "(s, &d, sat);");
  w.line("return status;");
  w.close();
}

void VariantEmitter::emit_q15_reciprocal(CodeWriter& w) const {
  const int fc = ar().fmt(Qty::kCovariance).frac;
  const int fi = ar().fmt(Qty::kInverseCovariance).frac;
  const int k = 29 - fc - fi;  // raw 1/v = y 2^(z - k), y = 2^29/m, m = v 2^z
  std::string seeds;
  for (int i = 0; i < 16; ++i) seeds += (i ? ", " : "") + std::to_string(std::lround(std::ldexp(1.0, 19) / (i + 16.5)));
  w.line("/* 2^19/(i + 16.5): the seed of 2^29/m for m in [(16 + i) 2^10, (17 + i) 2^10). */");
  w.line("static ONESHOT_CONST_TABLE const uint16_t " + fn("recip_seed") + "[16] = {" + seeds + "};");
  w.line("/* 1/v for 0 < v < 2^15 (reciprocal<>, 16-bit): m = v 2^z in [2^14, 2^15), y = 2^29/m from the seed,");
  w.line("   two Newton steps y += y (2^29 - m y) / 2^29 and one remainder correction (all in 32 bits),");
  w.line("   then y 2^(z - " + std::to_string(k) + ") rounded half up; beyond the format it saturates. */");
  w.open("static int16_t " + fn("reciprocal") + "(int16_t v, uint8_t *sat) {");
  w.line("int32_t m = v, y, e;");
  w.line("int16_t z = 0, shift;");
  w.open("if (v <= 0) {").line("*sat = 1u;").line("return INT16_MAX;").close();
  w.open("if (m < 128) {").line("m *= 256;").line("z += 8;").close();
  w.open("if (m < 2048) {").line("m *= 16;").line("z += 4;").close();
  w.open("if (m < 8192) {").line("m *= 4;").line("z += 2;").close();
  w.open("if (m < 16384) {").line("m *= 2;").line("z += 1;").close();
  w.line("y = " + fn("recip_seed") + "[(m >> 10) - 16];");
  w.line("e = INT32_C(536870912) - m * y;");
  w.line("y += (y * (e >> 9)) >> 20;");
  w.line("e = INT32_C(536870912) - m * y;");
  w.line("y += (y * (e >> 9)) >> 20;");
  w.line("e = INT32_C(536870912) - m * y;");
  w.open("if (e < 0) {").line("--y;").middle("} else if (e >= m) {").line("++y;").close();
  w.line("shift = (int16_t)(" + std::to_string(k) + " - z);");
  w.open("if (shift > 0) {")
      .line("y = shift >= 16 ? 0 : (y + (INT32_C(1) << (shift - 1))) >> shift;")
      .middle("} else if (shift < 0) {")
      .open("if (shift <= -16 || y > (INT32_C(32767) >> -shift)) {").line("*sat = 1u;").line("return INT16_MAX;").close()
      .line("y *= INT32_C(1) << -shift;")
      .close();
  w.open("if (y > INT32_C(32767)) {").line("*sat = 1u;").line("return INT16_MAX;").close();
  w.line("return (int16_t)y;");
  w.close();
}

}  // namespace oneshot::design::cjob
