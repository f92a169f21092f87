/// @file study_text.hpp
/// @brief The number and name formatting and the per-scenario cost entries that the study files'
///        summaries and reports share (study_dropping_*, study_sod_*, study_petc_*, study_oneshot_*).
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdio>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>

#include "oneshot/engine/sweep_statistics.hpp"

namespace oneshot::study {

/// A number for JSON: null when not finite (a diverged run is shown, and the JSON stays valid).
inline nlohmann::json finite_or_null(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); }

/// `v` in printf `format` for a markdown table, "—" when not finite (a diverged loop).
inline std::string md_cell(double v, const char* format) {
  if (!std::isfinite(v)) return "—";
  char b[48];
  std::snprintf(b, sizeof b, format, v);
  return b;
}

/// A JSON number in printf `format`, "—" when null or not finite.
inline std::string md_cell(const nlohmann::json& v, const char* format) {
  return v.is_number() ? md_cell(v.get<double>(), format) : std::string("—");
}

/// The file stem of approach `a` (index from 0) named `name`: trace_<a+1>_<name with every
/// character outside [A-Za-z0-9._-] as '_'> (names come from the file: never a path).
inline std::string trace_stem(std::size_t a, const std::string& name) {
  std::string out = "trace_" + std::to_string(a + 1) + "_";
  for (char c : name) {
    const bool ok = (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '.' || c == '_' || c == '-';
    out += ok ? c : '_';
  }
  return out;
}

/// Approach `a`'s figures in scenario `x` of the summary `sm` into the per-scenario entry `e`
/// under its `name`: cost_mean, cost_ci95 (over seeds), ratio_to_<ref> and its _ci95 (the mean of
/// the per-seed ratios to the first approach `ref`); null where not finite.
inline void add_scenario_cost(nlohmann::json& e, const engine::SweepSummary& sm, const std::string& name, const std::string& ref,
                              std::size_t a, std::size_t x) {
  e["cost_mean"][name] = finite_or_null(sm.per_scenario[a][x].mean);
  e["cost_ci95"][name] = finite_or_null(sm.per_scenario[a][x].ci95);
  e["ratio_to_" + ref][name] = finite_or_null(sm.per_scenario_ratio[a][x].mean);
  e["ratio_to_" + ref + "_ci95"][name] = finite_or_null(sm.per_scenario_ratio[a][x].ci95);
}

/// The per-scenario costs of a study file's sweep `r` summarized in `sm`: j["per_scenario"], one
/// entry per scenario ({"name"} and add_scenario_cost() of every approach, the reference the first
/// approach), and the markdown table scenario × approach of the mean costs onto `md`.
inline void add_per_scenario_costs(nlohmann::json& j, std::ostringstream& md, const engine::SweepResults& r,
                                   const engine::SweepSummary& sm) {
  const engine::SweepSpec& spec = r.spec;
  md << "\n| scenario |";
  for (const std::string& a : spec.approaches) md << " " << a << " |";
  md << "\n|---|";
  for (std::size_t a = 0; a < spec.approaches.size(); ++a) md << "---|";
  md << "\n";
  for (std::size_t x = 0; x < spec.scenarios.size(); ++x) {
    nlohmann::json e = {{"name", spec.scenarios[x]}};
    md << "| " << spec.scenarios[x] << " |";
    for (std::size_t a = 0; a < spec.approaches.size(); ++a) {
      add_scenario_cost(e, sm, spec.approaches[a], spec.approaches[0], a, x);
      md << " " << md_cell(sm.per_scenario[a][x].mean, "%.6g") << " |";
    }
    md << "\n";
    j["per_scenario"].push_back(e);
  }
}

}  // namespace oneshot::study
