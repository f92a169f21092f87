/// @file study_sod_runner.cpp
/// @brief A "study": "sod" file's sweep, its summary and `study run` (see study_sod_runner.hpp).
#include "study_sod_runner.hpp"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <iterator>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "oneshot/engine/study_file.hpp"
#include "oneshot/engine/sweep.hpp"
#include "oneshot/engine/sweep_statistics.hpp"
#include "oneshot/util/output_files.hpp"
#include "oneshot/util/statistics.hpp"
#include "study_sod_study.hpp"
#include "study_text.hpp"

namespace oneshot::study {
namespace {

const char* const kSodMetrics[] = {"cost",  "e1",          "e2",          "e1_tail", "e2_tail", "nees",      "sends1",
                                   "sends2", "time_sends1", "time_sends2", "lost1",   "lost2",   "detected1", "detected2"};

/// Metric `m` of approach `a` in scenario `x`, one value per seed.
std::vector<double> sod_cell(const engine::SweepResults& r, std::size_t a, std::size_t x, std::size_t m) {
  std::vector<double> v;
  for (std::size_t k = 0; k < r.spec.seeds; ++k) v.push_back(r.at(a, x, k, m));
  return v;
}

}  // namespace

engine::SweepResults run_sod_sweep(const SodStudy& s, std::size_t seeds, unsigned threads, const engine::Shard& shard) {
  engine::SweepSpec spec = sod_sweep_spec(s, seeds, "run-sod");
  for (const char* m : kSodMetrics) spec.metrics.emplace_back(m);
  const SodDesigns d = sod_designs(s, spec.seeds, threads);
  std::vector<std::vector<sod::RunConfig>> runs(s.approaches.size());
  nlohmann::json settings = nlohmann::json::array();
  for (std::size_t a = 0; a < s.approaches.size(); ++a) {
    nlohmann::json per = nlohmann::json::array();
    for (std::size_t x = 0; x < s.scenarios.size(); ++x) {
      runs[a].push_back(sod_run_config(s, d, a, x));
      per.push_back(sod_run_json(runs[a].back()));
    }
    settings.push_back({{"name", s.approaches[a].name}, {"kind", s.approaches[a].kind}, {"per_scenario", per}});
  }
  nlohmann::json losses = nlohmann::json::array();
  for (const SodScenario& x : s.scenarios) losses.push_back(x.loss);
  spec.config = {{"study_file", s.source}, {"plant", s.model.plant_name}, {"plant_file", s.plant_path},
                 {"links", {s.links[0], s.links[1]}}, {"scenario_loss", losses}, {"approaches", settings},
                 {"designs", d.json}};
  return engine::run_sweep(
      spec, shard, threads,
      [&s, &runs](std::size_t a, std::size_t x, std::uint64_t seed) {
        const sod::RunResult m = sod::simulate_run(s.model, runs[a][x], seed);
        return std::vector<double>{m.e[0] + m.e[1], m.e[0],     m.e[1],         m.e_tail[0],    m.e_tail[1],
                                   m.nees,          m.sends[0], m.sends[1],     m.time_sends[0], m.time_sends[1],
                                   m.lost[0],       m.lost[1],  m.detected[0],  m.detected[1]};
      },
      "study run (sod)");
}

nlohmann::json sod_run_outputs(const engine::SweepResults& r, const std::string& out_dir, bool plots) {
  static_cast<void>(plots);  // no plot: the table and the runs' CSV (study report draws the cost plot)
  util::make_directory(out_dir);
  const engine::SweepSpec& spec = r.spec;
  const std::size_t na = spec.approaches.size(), ns = spec.scenarios.size();
  const engine::SweepSummary sm = engine::summarize_metric(r, r.metric("cost"), 0);
  const std::string ref = spec.approaches[0];
  nlohmann::json j;
  j["study"] = "sod";
  j["experiment"] = "study run";
  j["study_file"] = spec.config.at("study_file");
  j["plant"] = spec.config.at("plant");
  j["first_seed"] = spec.first_seed;
  j["seeds"] = spec.seeds;
  j["runs"] = spec.runs();
  j["cost"] = "e1 + e2: (1/N) sum_k |x_k - xhat_k|^2 of the run";
  j["settings"] = spec.config.at("approaches");
  j["designs"] = spec.config.at("designs");
  const std::vector<std::string> links = spec.config.at("links").get<std::vector<std::string>>();
  const auto stat = [&](std::size_t a, std::size_t x, const std::string& m) { return util::summarize(sod_cell(r, a, x, r.metric(m))); };
  const auto over_scenarios = [&](std::size_t a, const std::string& m) {
    std::vector<double> v;
    for (std::size_t x = 0; x < ns; ++x) {
      const std::vector<double> c = sod_cell(r, a, x, r.metric(m));
      v.insert(v.end(), c.begin(), c.end());
    }
    return util::summarize(v).mean;
  };
  std::ostringstream md;
  md << "| approach | kind | mean cost e1 + e2 | 95 % CI | ratio to " << ref
     << " (95 % CI) | e1 | e2 | NEES (2 = consistent) | packets 1 | packets 2 |\n|---|---|---|---|---|---|---|---|---|---|\n";
  for (std::size_t a = 0; a < na; ++a) {
    const std::string& nm = spec.approaches[a];
    const std::string kind = spec.config.at("approaches")[a].at("kind").get<std::string>();
    nlohmann::json link_totals;
    for (std::size_t i = 0; i < links.size(); ++i) {
      const std::string n = std::to_string(i + 1);
      double sent = 0, lost = 0, time_sent = 0, detected = 0;
      for (std::size_t x = 0; x < ns; ++x)
        for (std::size_t k = 0; k < spec.seeds; ++k) {
          sent += r.at(a, x, k, r.metric("sends" + n));
          lost += r.at(a, x, k, r.metric("lost" + n));
          time_sent += r.at(a, x, k, r.metric("time_sends" + n));
          detected += r.at(a, x, k, r.metric("detected" + n));
        }
      j["links"][nm][links[i]] = {{"sent", sent}, {"delivered", sent - lost}, {"lost", lost}, {"time_rule_sent", time_sent},
                                  {"detected", detected}};
    }
    const double e1 = over_scenarios(a, "e1"), e2 = over_scenarios(a, "e2"), nees = over_scenarios(a, "nees");
    const double p1 = over_scenarios(a, "sends1"), p2 = over_scenarios(a, "sends2");
    j["approaches"][nm] = {{"kind", kind},
                           {"cost_mean", finite_or_null(sm.value[a].mean)},
                           {"cost_ci95", finite_or_null(sm.value[a].ci95)},
                           {"ratio_to_" + ref, finite_or_null(sm.ratio_of_means[a])},
                           {"ratio_mean", finite_or_null(sm.ratio[a].mean)},
                           {"ratio_ci95", finite_or_null(sm.ratio[a].ci95)},
                           {"e1_mean", finite_or_null(e1)},
                           {"e2_mean", finite_or_null(e2)},
                           {"nees_mean", finite_or_null(nees)},
                           {"packets_mean", {finite_or_null(p1), finite_or_null(p2)}}};
    md << "| " << nm << " | " << kind << " | " << md_cell(sm.value[a].mean, "%.6g") << " | ± " << md_cell(sm.value[a].ci95, "%.3g") << " | "
       << md_cell(sm.ratio_of_means[a], "%.4f") << " ± " << md_cell(sm.ratio[a].ci95, "%.4f") << " | " << md_cell(e1, "%.4g") << " | "
       << md_cell(e2, "%.4g") << " | " << md_cell(nees, "%.4g") << " | " << md_cell(p1, "%.5g") << " | " << md_cell(p2, "%.5g") << " |\n";
  }
  engine::add_order_by_mean(j, r, sm);
  if (!sm.paired.empty()) j["paired_differences"] = engine::paired_differences_json(r, sm);
  md << "\n| scenario | xi |";  // per approach: e1, e2, NEES, packets of both nodes
  for (std::size_t a = 0; a < na; ++a) md << " " << spec.approaches[a] << " e1 | e2 | NEES | packets 1+2 |";
  md << "\n|---|---|";
  for (std::size_t a = 0; a < na; ++a) md << "---|---|---|---|";
  md << "\n";
  for (std::size_t x = 0; x < ns; ++x) {
    const double xi = spec.config.at("scenario_loss").at(x).get<double>();
    nlohmann::json e = {{"name", spec.scenarios[x]}, {"loss", xi}};
    md << "| " << spec.scenarios[x] << " | " << xi << " |";
    for (std::size_t a = 0; a < na; ++a) {
      const std::string& nm = spec.approaches[a];
      add_scenario_cost(e, sm, nm, ref, a, x);
      for (const char* m : {"e1", "e2", "e1_tail", "e2_tail", "nees"}) e[m][nm] = util::mean_ci_json(stat(a, x, m));
      for (int i = 1; i <= 2; ++i) {
        const std::string n = std::to_string(i);
        e["packets"][nm].push_back(util::mean_ci_json(stat(a, x, "sends" + n)));
        e["time_rule_sends"][nm].push_back(util::mean_ci_json(stat(a, x, "time_sends" + n)));
        e["losses"][nm].push_back(util::mean_ci_json(stat(a, x, "lost" + n)));
        e["detected_losses"][nm].push_back(util::mean_ci_json(stat(a, x, "detected" + n)));
      }
      md << " " << md_cell(stat(a, x, "e1").mean, "%.4g") << " | " << md_cell(stat(a, x, "e2").mean, "%.4g") << " | "
         << md_cell(stat(a, x, "nees").mean, "%.4g") << " | "
         << md_cell(stat(a, x, "sends1").mean + stat(a, x, "sends2").mean, "%.5g") << " |";
    }
    md << "\n";
    j["per_scenario"].push_back(e);
  }
  j["markdown"] = md.str();
  engine::write_runs_csv(r, util::path_in(out_dir, "runs.csv"), util::NonFinite::kMissing);
  j["files"] = {"runs.csv"};
  return j;
}

}  // namespace oneshot::study
