/// @file c_job_q15_advance.cpp
/// @brief The q15 variants' discretization: a one-level table of Φ, Γ, Q_d at every grid
///        point k·g (0 < k·g ≤ range, computed exactly in double and stored in the filter's own
///        16-bit formats, so loading is a copy), the residual polynomial for the part of τ
///        between grid points, and sequential predictions over the pieces instead of
///        compositions: Φ(a+b) = Φ(b)Φ(a) for a time-invariant plant with the input held, so
///        predicting over a then over b equals predicting once over a+b, at one prediction per
///        piece (no 16-bit composition of Q_d).
#include <cmath>

#include "c_job/c_job_variant.hpp"
#include "oneshot/design/dimension_dispatch.hpp"
#include "oneshot/design/fixed_size.hpp"
#include "oneshot/generic_discretizer.hpp"

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
    w.open("if (residual_us > 0) {").line(fn("residual") + "(residual_us, &d, sat);").line(fn("predict") + "(s, &d, sat);").close();
    w.close();
  } else {
    w.line("/* tau_us is a multiple of g here (the job rounds tau to the grid first). */");
  }
  w.open("if (index > 0) {").line(fn("load") + "((uint8_t)(index - 1), &d);").line(fn("predict") + "(s, &d, sat);").close();
  w.line("return status;");
  w.close();
}

}  // namespace oneshot::design::cjob
