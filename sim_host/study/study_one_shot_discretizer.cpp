/// @file study_one_shot_discretizer.cpp
/// @brief The one-shot loops' discretizer of a study file (see study_one_shot_discretizer.hpp).
#include "study_one_shot_discretizer.hpp"

#include <algorithm>
#include <cmath>
#include <exception>
#include <sstream>
#include <stdexcept>
#include <string>

#include "oneshot/design/structure_analysis.hpp"
#include "oneshot/plant_structure.hpp"
#include "oneshot/table_discretizer.hpp"
#include "study_fields.hpp"

namespace oneshot::study {
namespace {

using ncs::kM;
using ncs::kN;
using ncs::kP;

/// max |a − exact| / max |exact| over the entries of an r×c matrix.
template <typename M>
double relative_error(const M& a, const design::DenseMatrix& exact, std::size_t r, std::size_t c) {
  double diff = 0;
  double scale = 0;
  for (std::size_t i = 0; i < r; ++i) {
    for (std::size_t j = 0; j < c; ++j) {
      diff = std::max(diff, std::fabs(a(i, j) - exact(i, j)));
      scale = std::max(scale, std::fabs(exact(i, j)));
    }
  }
  return scale > 0 ? diff / scale : diff;
}

/// Φ, Γ, Q_d over τ_us from the table `view` with sub-grid rule kSub (τ quantized first, as the
/// filters do: TableDiscretizer::quantize()).
template <SubGrid kSub, typename View>
ncs::OneShotTriple evaluate(const View& view, std::int32_t& tau_us) {
  using Table = TableDiscretizer<ncs::Fmt, DenseStructure<kN, kM, kP>, double, OutOfRange::kExtend, kSub>;
  const Table table(view);
  tau_us = table.quantize(tau_us);
  Discretization<ncs::Fmt, kN, kM> d{NoInit{}};
  const Status st = table.discretize(tau_us, d, WithQd::kYes);
  if (st == Status::kClamped) throw std::invalid_argument("one-shot table: tau outside [0, 4 range]");
  return ncs::OneShotTriple{d.phi, d.gamma, d.qd};
}

}  // namespace

ncs::OneShotTriple evaluate_one_shot_table(const design::TableData<double>& table, OneShotDiscretizer kind, std::int32_t& tau_us) {
  const auto view = table.view<SlotIdFor<kN, kM>>();
  if (kind == OneShotDiscretizer::kTable) return evaluate<SubGrid::kExact>(view, tau_us);
  if (kind == OneShotDiscretizer::kNearest) return evaluate<SubGrid::kNearest>(view, tau_us);
  throw std::invalid_argument("one-shot table: the generic discretizer has no table");
}

const char* name(OneShotDiscretizer d) {
  switch (d) {
    case OneShotDiscretizer::kTable:
      return "table";
    case OneShotDiscretizer::kNearest:
      return "nearest";
    case OneShotDiscretizer::kGeneric:
      break;
  }
  return "generic";
}

std::optional<OneShotDiscretizer> one_shot_discretizer_named(const std::string& word) {
  for (OneShotDiscretizer d : {OneShotDiscretizer::kGeneric, OneShotDiscretizer::kTable, OneShotDiscretizer::kNearest})
    if (word == name(d)) return d;
  return std::nullopt;
}

OneShotDiscretization design_one_shot_discretization(const ncs::Context& ctx, OneShotDiscretizer kind,
                                                     const std::string& field, const std::string& plant_field) {
  OneShotDiscretization out;
  out.kind = kind;
  out.tau_us = ctx.period_us();
  if (kind == OneShotDiscretizer::kGeneric) return out;
  const design::PlantDescription& plant = ctx.plant();
  if (!plant.has_table) {
    refuse(field, std::string("'") + name(kind) + "' needs the plant's Phi(tau) table grid: its plant has no 'table' section "
                  "{granularity_us, range_us, max_bytes} (in the plant file, or plant.continuous.table; h a multiple of the granularity, "
                  "range >= h)");
  }
  const design::DesignResult& dr = ctx.design();
  std::shared_ptr<const design::TableData<double>> table;
  try {
    const design::PlantPatterns patterns = design::analyse_structure(plant, dr);
    table = std::make_shared<const design::TableData<double>>(design::build_table<double>(plant, dr, patterns));
  } catch (const std::exception& e) {
    refuse(plant_field, std::string("its Phi/Gamma/Q_d table (") + name(kind) + ", " + field + "): " + e.what());
  }
  const design::TableData<double>& data = *table;
  std::int32_t tau = out.tau_us;
  const ncs::OneShotTriple t = evaluate_one_shot_table(data, kind, tau);
  out.tau_us = tau;
  out.triple = std::make_shared<const ncs::OneShotTriple>(t);
  out.table = table;
  out.table_bytes = data.bytes();
  out.granularity_us = data.granularity_us;
  out.range_us = data.range_us;
  out.levels = data.radix.size();
  out.entries = data.entry_time_us.size();
  out.phi_rel_error = relative_error(t.phi, dr.phi_h, kN, kN);
  out.gamma_rel_error = relative_error(t.gamma, dr.gamma_h, kN, kM);
  out.qd_rel_error = relative_error(t.qd, dr.qd_h, kN, kN);
  return out;
}

nlohmann::json discretizer_json(const OneShotDiscretization& d) {
  nlohmann::json e = {{"kind", name(d.kind)}, {"tau_us", d.tau_us}};
  if (d.kind == OneShotDiscretizer::kGeneric) {
    e["source"] = "the design step's exact Phi(h), Gamma(h), Q_d(h) (matrix exponentials)";
    return e;
  }
  e["source"] = d.kind == OneShotDiscretizer::kTable ? "the plant's table, exact between grid points (residual polynomial)"
                                                     : "the plant's table at the nearest grid point";
  e["table"] = {{"bytes", d.table_bytes}, {"storage", "double"}, {"granularity_us", d.granularity_us},
                {"range_us", d.range_us},  {"levels", d.levels},   {"entries", d.entries}};
  e["relative_error_at_h"] = {{"phi", d.phi_rel_error}, {"gamma", d.gamma_rel_error}, {"qd", d.qd_rel_error}};
  return e;
}

std::string describe_discretizer(const nlohmann::json& d) {
  std::ostringstream o;
  o << "discretizer " << d.at("kind").get<std::string>() << " at tau = " << d.at("tau_us") << " us: " << d.at("source").get<std::string>();
  if (d.contains("table")) {
    const nlohmann::json& t = d.at("table");
    const nlohmann::json& err = d.at("relative_error_at_h");
    o << "; table " << t.at("bytes") << " B (" << t.at("storage").get<std::string>() << "), grid " << t.at("granularity_us")
      << " us over [0, " << t.at("range_us") << "] us, " << t.at("levels") << " levels, " << t.at("entries")
      << " entries; relative error at h: Phi " << err.at("phi") << ", Gamma " << err.at("gamma") << ", Q_d " << err.at("qd");
  }
  return o.str();
}

}  // namespace oneshot::study
