/// @file c_job_q15.cpp
/// @brief The q15 variants' own pieces. Discretization: a one-level table of Φ, Γ, Q_d at every grid
///        point k·g (0 < k·g ≤ range, computed exactly in double and stored in the filter's own
///        16-bit formats, so loading is a copy), the residual polynomial for the part of τ
///        between grid points, and sequential predictions over the pieces instead of
///        compositions: Φ(a+b) = Φ(b)Φ(a) for a time-invariant plant with the input held, so
///        predicting over a then over b equals predicting once over a+b, at one prediction per
///        piece (no 16-bit composition of Q_d). Reciprocal: 1/S from a 16-bit S by a seed table,
///        two Newton steps and a one-step remainder correction, in 32-bit arithmetic.
#include <algorithm>
#include <cmath>
#include <tuple>

#include "c_job/c_job_variant.hpp"
#include "oneshot/design/dimension_dispatch.hpp"
#include "oneshot/design/fixed_size.hpp"
#include "oneshot/generic_discretizer.hpp"
#include "oneshot/table_view.hpp"

namespace oneshot::design::cjob {

namespace {

/// Φ, Γ, Q_d (free entries, triple order) at t = k·g, k = 1 … K, in double.
template <std::size_t N, std::size_t M>
std::vector<std::vector<double>> grid_triples(const PlantDescription& plant, const DesignResult& d, std::int32_t g,
                                              std::size_t k_max,
                                              const std::vector<std::pair<std::size_t, std::size_t>>& phi,
                                              const std::vector<std::pair<std::size_t, std::size_t>>& gamma,
                                              const std::vector<std::pair<std::size_t, std::size_t>>& qd) {
  const GenericDiscretizer<UniformFormat<double>, N, M> gen(continuous_model_per_us<double, N, M>(plant, d));
  std::vector<std::vector<double>> rows;
  for (std::size_t k = 1; k <= k_max; ++k) {
    Discretization<UniformFormat<double>, N, M> dd;
    const auto t = static_cast<std::int32_t>(k) * g;
    if (gen.discretize(t, dd, WithQd::kYes) != Status::kOk) {
      throw DesignError("C job q15: the exponential of A·t fails at t = " + std::to_string(t) + " us");
    }
    std::vector<double> row;
    for (const auto& [i, j] : phi) row.push_back(dd.phi(i, j));
    for (const auto& [i, j] : gamma) row.push_back(dd.gamma(i, j));
    for (const auto& [i, j] : qd) row.push_back(dd.qd(i, j));
    rows.push_back(row);
  }
  return rows;
}

}  // namespace

std::size_t VariantEmitter::q15_entries() const {
  return static_cast<std::size_t>(spec_.table.range_us / spec_.table.granularity_us);
}

void VariantEmitter::emit_q15_table(CodeWriter& w) const {
  const std::int32_t g = spec_.table.granularity_us;
  const std::size_t k_max = q15_entries();
  const auto rows = with_dimensions(n_, m_, 1, [&](auto n, auto m, auto) {
    return grid_triples<decltype(n)::value, decltype(m)::value>(plant_, design_, g, k_max, phi_free_, gamma_free_,
                                                                qd_free_);
  });
  const std::size_t slots = phi_free_.size() + gamma_free_.size() + qd_free_.size();
  w.line("/* Phi, Gamma, Q_d at t = k x " + std::to_string(g) + " us, k = 1.." + std::to_string(k_max) +
         " (exact, rounded once into the filter's formats: loading is a copy). */");
  w.open("static ONESHOT_CONST_TABLE const int16_t " + fn("grid") + "[" + std::to_string(k_max) + "][" +
         std::to_string(std::max<std::size_t>(slots, 1)) + "] = {");
  for (std::size_t k = 0; k < rows.size(); ++k) {
    std::string row = "{";
    std::size_t s = 0;
    const auto add = [&](Qty q, double v, const char* what) {
      row += (s++ ? ", " : "") + ar().constant(q, v, std::string(what) + "(" + std::to_string((k + 1) * static_cast<std::size_t>(g)) + " us)").expr;
    };
    for (std::size_t i = 0; i < phi_free_.size(); ++i) add(Qty::kTransition, rows[k][i], "Phi");
    for (std::size_t i = 0; i < gamma_free_.size(); ++i) add(Qty::kInputGain, rows[k][phi_free_.size() + i], "Gamma");
    for (std::size_t i = 0; i < qd_free_.size(); ++i)
      add(Qty::kCovariance, rows[k][phi_free_.size() + gamma_free_.size() + i], "Q_d");
    if (slots == 0) row += "0";
    w.line(row + (k + 1 < rows.size() ? "}," : "}"));
  }
  w.close("};");
}

void VariantEmitter::emit_q15_load(CodeWriter& w) const {
  w.line("/* d = the grid entry k + 1 (a copy: the table holds the filter's formats). */");
  w.open("static void " + fn("load") + "(uint8_t k, " + triple_type() + " *d) {");
  std::size_t s = 0;
  const auto copy = [&](const char* member, std::size_t count) {
    for (std::size_t i = 0; i < count; ++i)
      w.line(std::string("d->") + member + "[" + std::to_string(i) + "] = " + fn("grid") + "[k][" + std::to_string(s++) + "];");
  };
  copy("phi", phi_free_.size());
  copy("gamma", gamma_free_.size());
  copy("qd", qd_free_.size());
  if (s == 0) w.line("(void)k;").line("(void)d;");
  w.close();
}

void VariantEmitter::emit_q15_residual(CodeWriter& w) const {
  const TableText& t = spec_.table;
  const std::int32_t g = t.granularity_us;
  const int f = ar().fmt(Qty::kFraction).frac;
  if (f < 1 || f > 15) throw DesignError("C job q15: the sub-grid fraction needs 1..15 fractional bits");
  // Where each slot goes: the finest format among its uses.
  std::vector<int> out_frac(t.slots, -1000);
  std::vector<std::tuple<std::string, Qty, std::int16_t>> uses;
  for (std::size_t k = 0; k < phi_free_.size(); ++k)
    uses.emplace_back("d->phi[" + std::to_string(k) + "]", Qty::kTransition, t.phi_slot[phi_free_[k].first * n_ + phi_free_[k].second]);
  for (std::size_t k = 0; k < gamma_free_.size(); ++k)
    uses.emplace_back("d->gamma[" + std::to_string(k) + "]", Qty::kInputGain, t.gamma_slot[gamma_free_[k].first * m_ + gamma_free_[k].second]);
  for (std::size_t k = 0; k < qd_free_.size(); ++k)
    uses.emplace_back("d->qd[" + std::to_string(k) + "]", Qty::kCovariance, t.qd_slot[qd_free_[k].first * n_ + qd_free_[k].second]);
  for (const auto& [dest, q, slot] : uses)
    if (slot >= 0) out_frac[static_cast<std::size_t>(slot)] = std::max(out_frac[static_cast<std::size_t>(slot)], ar().fmt(q).frac);
  w.line("/* d over delta = residual_us < g from each slot's Taylor polynomial in r = delta/g (Horner in");
  w.line("   16x16->32 steps; terms below 1/64 LSB of the slot's destination left out; the last product");
  w.line("   rounded straight into the destination's format). */");
  w.open("static void " + fn("residual") + "(int32_t residual_us, " + triple_type() + " *d) {");
  const auto scale = static_cast<std::uint32_t>(((std::uint64_t{1} << (f + 16)) + static_cast<std::uint64_t>(g) / 2) /
                                                static_cast<std::uint64_t>(g));
  w.line("const int16_t r = (int16_t)(((uint32_t)residual_us * " + u32_literal(scale) +
         " + UINT32_C(0x8000)) >> 16);  /* residual_us < g: r < 2^" + std::to_string(f) + " */");
  const std::string half = int_literal(std::int64_t{1} << (f - 1), 32);
  // Per slot: an expression and its fraction (value = expr 2^-frac), or empty for 0.
  std::vector<std::string> expr(t.slots);
  std::vector<int> frac(t.slots, 0);
  std::vector<double> bound(t.slots, 0);
  for (std::size_t s = 0; s < t.slots; ++s) {
    if (out_frac[s] == -1000) continue;
    std::vector<long long> c = t.coeff_raw[s];
    const int shift_out = t.residual_frac[s] - out_frac[s];
    double dropped = 0;
    while (!c.empty() && dropped + std::fabs(static_cast<double>(c.back())) <= std::ldexp(1.0, shift_out - 6)) {
      dropped += std::fabs(static_cast<double>(c.back()));
      c.pop_back();
    }
    if (c.empty()) continue;  // the whole slot rounds to 0 in its destinations
    double sum = 0;
    for (long long v : c) sum += std::fabs(static_cast<double>(v));
    const std::string v = "v" + std::to_string(s);
    const int low = t.low[s];
    if (c.size() == 1 && low == 0) {
      expr[s] = int_literal(c[0], 16);
      frac[s] = t.residual_frac[s];
      bound[s] = std::fabs(static_cast<double>(c[0]));
      continue;
    }
    w.line("int16_t " + v + " = " + int_literal(c.back(), 16) + ";");
    for (std::size_t k = c.size() - 1; k > 0; --k)
      w.line(v + " = (int16_t)(((os_q15_m(" + v + ", r) + " + half + ") >> " + std::to_string(f) + ") + " +
             int_literal(c[k - 1], 16) + ");");
    for (int k = 0; k + 1 < low; ++k)
      w.line(v + " = (int16_t)((os_q15_m(" + v + ", r) + " + half + ") >> " + std::to_string(f) + ");");
    if (low > 0) {  // the last r: kept as the 32-bit product
      expr[s] = "os_q15_m(" + v + ", r)";
      frac[s] = t.residual_frac[s] + f;
      bound[s] = (sum + static_cast<double>(c.size() + static_cast<std::size_t>(low))) * std::ldexp(1.0, f);
    } else {
      expr[s] = v;
      frac[s] = t.residual_frac[s];
      bound[s] = sum + static_cast<double>(c.size());
    }
  }
  for (const auto& [dest, q, slot] : uses) {
    if (slot == ::oneshot::kSlotZero || (slot >= 0 && expr[static_cast<std::size_t>(slot)].empty())) {
      w.line(dest + " = 0;");
    } else if (slot == ::oneshot::kSlotOne) {
      bool sat = false;
      const std::string one = ar().one(q, sat);
      if (sat) throw DesignError("C job q15: a structural one does not fit its format");
      w.line(dest + " = " + one + ";");
    } else {
      const auto s = static_cast<std::size_t>(slot);
      const int sh = frac[s] - ar().fmt(q).frac;
      if (sh < 0 || bound[s] + std::ldexp(1.0, std::max(sh - 1, 0)) > 2147483647.0)
        throw DesignError("C job q15: a residual slot is coarser than its destination");
      const double out = std::ldexp(bound[s], -sh) + 1;
      if (out > 32767.0) throw DesignError("C job q15: a residual slot exceeds its destination's format");
      w.line(dest + " = (int16_t)(" + (sh == 0 ? expr[s] : "((int32_t)" + expr[s] + " + " + int_literal(std::int64_t{1} << (sh - 1), 32) + ") >> " + std::to_string(sh)) + ");");
    }
  }
  w.close();
}

void VariantEmitter::emit_q15_advance(CodeWriter& w) {
  const TableText& t = spec_.table;
  const std::int32_t g = t.granularity_us;
  const std::string range = int_literal(t.range_us, 32);
  const auto k_max = static_cast<std::uint32_t>(q15_entries());
  const auto max_arg = static_cast<std::uint32_t>(plant_.period_us + tau_bound_us());
  w.line("/* Predict over tau_us (TableDiscretizer::discretize's intervals, OutOfRange::kExtend): tau < 0");
  w.line("   clamps to 0; beyond the range, whole ranges (up to 4) then the remainder; each piece is one");
  w.line("   prediction: the residual polynomial for tau mod g, the grid entry for the rest. */");
  w.open("static uint8_t " + fn("advance") + "(" + state_type() + " *s, int32_t tau_us, uint8_t *sat) {");
  w.line(triple_type() + " d;");
  w.line("uint8_t status = ONESHOT_JOB_STATUS_OK;");
  w.line("int32_t index;");
  w.open("if (tau_us < 0) {").line("tau_us = 0;").line("status = ONESHOT_JOB_STATUS_CLAMPED;").close();
  w.open("if (tau_us > " + range + ") {");
  w.line("int32_t repeats = " + divide_by_constant("tau_us", static_cast<std::uint32_t>(t.range_us), max_arg, divisions_) + ";");
  w.line("int32_t remainder = tau_us - repeats * " + range + ";");
  w.line("status = ONESHOT_JOB_STATUS_EXTENDED;");
  w.open("if (repeats > 4 || (repeats == 4 && remainder > 0)) {")
      .line("repeats = 4;")
      .line("remainder = 0;")
      .line("status = ONESHOT_JOB_STATUS_CLAMPED;")
      .close();
  w.line(fn("load") + "((uint8_t)" + std::to_string(k_max - 1) + "u, &d);");
  w.open("for (; repeats > 0; --repeats) {").line(fn("predict") + "(s, &d, sat);").close();
  w.line("tau_us = remainder;");
  w.close();
  w.line("index = " + divide_by_constant("tau_us", static_cast<std::uint32_t>(g), static_cast<std::uint32_t>(t.range_us), divisions_) + ";");
  if (spec_.exact_subgrid) {
    w.open("{").line("const int32_t residual_us = tau_us - index * " + int_literal(g, 32) + ";");
    w.open("if (residual_us > 0) {").line(fn("residual") + "(residual_us, &d);").line(fn("predict") + "(s, &d, sat);").close();
    w.close();
  } else {
    w.line("/* tau_us is a multiple of g here (the job rounds tau to the grid first). */");
  }
  w.open("if (index > 0) {").line(fn("load") + "((uint8_t)(index - 1), &d);").line(fn("predict") + "(s, &d, sat);").close();
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
