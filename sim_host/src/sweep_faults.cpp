/// @file sweep_faults.cpp
/// @brief Fault metrics of a study table (see sweep_faults.hpp).
#include "oneshot/sim/sweep_faults.hpp"

#include <cmath>
#include <cstdio>
#include <sstream>

#include "oneshot/util/statistics.hpp"

namespace oneshot::sim {

const std::vector<std::string>& fault_metric_names() {
  static const std::vector<std::string> names = {"injected",         "corrupt", "refused_non_finite",
                                                 "refused_out_of_range", "refused_sequence", "stale",
                                                 "estimator_resets", "ratio_to_clean"};
  return names;
}

void add_fault_metrics(engine::SweepSpec& spec, const engine::FaultSpec& faults, const std::string& ratio_of) {
  if (faults.empty()) return;
  spec.config["inject"] = faults.text;
  spec.config["inject_ratio_of"] = ratio_of;
  for (const auto& m : fault_metric_names()) spec.metrics.push_back(m);
}

void append_fault_values(std::vector<double>& values, const RunFaultCounts& c) {
  values.insert(values.end(), {c.injected, c.corrupt, c.refused_non_finite, c.refused_out_of_range, c.refused_sequence, c.stale,
                               c.estimator_resets, c.ratio_to_clean});
}

nlohmann::json fault_row(const engine::SweepResults& r, std::size_t a, std::size_t s) {
  if (!r.spec.config.contains("inject")) return nullptr;
  nlohmann::json row = nlohmann::json::object();
  for (const auto& name : fault_metric_names()) {
    const std::size_t m = r.metric(name);
    std::vector<double> v;
    for (std::size_t k = 0; k < r.spec.seeds; ++k) {
      const double x = r.at(a, s, k, m);
      if (std::isfinite(x)) v.push_back(x);
    }
    const util::Summary sm = util::summarize(v);
    const auto finite_or_null = [](double x) { return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(nullptr); };
    row[name] = {{"mean", finite_or_null(sm.mean)}, {"ci95", finite_or_null(sm.ci95)}, {"n", v.size()}};
  }
  return row;
}

std::string fault_markdown(const engine::SweepResults& r) {
  if (!r.spec.config.contains("inject")) return "";
  const auto g = [](const nlohmann::json& v) {
    if (v.is_null()) return std::string("—");
    char b[32];
    std::snprintf(b, sizeof b, "%.3g", v.get<double>());
    return std::string(b);
  };
  std::ostringstream md;
  md << "Faults `" << r.spec.config.at("inject").get<std::string>() << "`, " << r.spec.seeds << " seeds from "
     << r.spec.first_seed << "; per run (mean); ratio = " << r.spec.config.at("inject_ratio_of").get<std::string>()
     << " faulted / clean, same seed (mean ± 95 % CI):\n\n"
     << "| approach | scenario | injected | corrupt | refused non-finite | refused out of range | refused sequence | stale | "
        "estimator resets | ratio to clean | finite runs |\n|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (std::size_t a = 0; a < r.spec.approaches.size(); ++a)
    for (std::size_t s = 0; s < r.spec.scenarios.size(); ++s) {
      const nlohmann::json row = fault_row(r, a, s);
      md << "| " << r.spec.approaches[a] << " | " << r.spec.scenarios[s];
      for (const char* m : {"injected", "corrupt", "refused_non_finite", "refused_out_of_range", "refused_sequence", "stale",
                            "estimator_resets"})
        md << " | " << g(row.at(m).at("mean"));
      const nlohmann::json& q = row.at("ratio_to_clean");
      md << " | " << g(q.at("mean")) << " ± " << g(q.at("ci95")) << " | " << q.at("n").get<std::size_t>() << "/"
         << r.spec.seeds << " |\n";
    }
  return md.str();
}

}  // namespace oneshot::sim
