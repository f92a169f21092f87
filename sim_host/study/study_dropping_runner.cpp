/// @file study_dropping_runner.cpp
/// @brief A "study": "dropping" file's sweep and its summary (see study_dropping_runner.hpp).
#include "study_dropping_runner.hpp"

#include <cmath>
#include <cstdio>
#include <iterator>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "oneshot/engine/sweep.hpp"
#include "oneshot/engine/sweep_statistics.hpp"
#include "oneshot/util/output_files.hpp"
#include "study_dropping_study.hpp"
#include "study_format.hpp"
#include "study_text.hpp"
#include "sweep_parts.hpp"

namespace oneshot::study {
namespace {

const char* const kDropMetrics[] = {"cost", "err", "trace_p", "gamma", "failed", "sent", "lost", "late", "refused"};

double drop_mean(const std::vector<double>& v) {
  double s = 0;
  std::size_t n = 0;
  for (double x : v)
    if (std::isfinite(x)) {
      s += x;
      ++n;
    }
  return n == 0 ? std::nan("") : s / static_cast<double>(n);
}

}  // namespace

engine::SweepSpec dropping_sweep_spec(const DroppingStudy& s, std::size_t seeds, const char* experiment) {
  engine::SweepSpec spec;
  spec.study = "study";
  spec.experiment = experiment;
  spec.approaches = s.approaches;
  spec.scenarios = s.scenarios;
  spec.first_seed = s.first_seed;
  spec.seeds = seeds == 0 ? s.seeds : seeds;
  return spec;
}

engine::SweepResults run_dropping_sweep(const DroppingStudy& s, std::size_t seeds, unsigned threads, const engine::Shard& shard) {
  engine::SweepSpec spec = dropping_sweep_spec(s, seeds, "run-dropping");
  for (const char* m : kDropMetrics) spec.metrics.emplace_back(m);
  nlohmann::json runs = nlohmann::json::array();
  for (std::size_t a = 0; a < s.approaches.size(); ++a) {
    nlohmann::json per = nlohmann::json::array();
    for (const dropping::RunConfig& c : s.runs[a]) per.push_back(dropping_run_json(c));
    runs.push_back({{"name", s.approaches[a]}, {"kind", s.kinds[a]}, {"per_scenario", per}});
  }
  spec.config = {{"study_file", s.source}, {"plant", s.plant.plant.name}, {"plant_digest", dropping::plant_digest(s.plant)},
                 {"link", s.link}, {"approaches", runs}};
  return engine::run_sweep(
      spec, shard, threads,
      [&s](std::size_t a, std::size_t x, std::uint64_t seed) {
        const dropping::RunConfig& c = s.runs[a][x];
        const dropping::RunMetrics m = dropping::run_closed_loop(s.plant, c, seed);
        const bool buffered = c.estimator == dropping::EstimatorKind::kBuffered;
        return std::vector<double>{m.cost,
                                   m.err,
                                   m.trace_p,
                                   m.gamma,
                                   m.failed ? 1.0 : 0.0,
                                   m.sent,
                                   m.lost,
                                   buffered ? m.over_delayed : m.stale,
                                   m.refused_non_finite + m.refused_sequence + m.corrupt};
      },
      "study run (dropping)");
}

nlohmann::json dropping_run_outputs(const engine::SweepResults& r, const std::string& out_dir, bool plots) {
  static_cast<void>(plots);  // no plot: the table and the runs' CSV
  util::make_directory(out_dir);
  const engine::SweepSpec& spec = r.spec;
  const std::size_t na = spec.approaches.size(), ns = spec.scenarios.size();
  const engine::SweepSummary sm = engine::summarize_metric(r, r.metric("cost"), 0);
  const std::string ref = spec.approaches[0];
  nlohmann::json j;
  j["study"] = "dropping";
  j["experiment"] = "study run";
  j["study_file"] = spec.config.at("study_file");
  j["plant"] = spec.config.at("plant");
  j["link"] = spec.config.at("link");
  j["first_seed"] = spec.first_seed;
  j["seeds"] = spec.seeds;
  j["runs"] = spec.runs();
  j["settings"] = spec.config.at("approaches");
  std::ostringstream md;
  md << "| approach | kind | mean cost J | 95 % CI | ratio to " << ref << " (95 % CI) | |x - xhat|^2 | tr P | gamma | failed |\n"
     << "|---|---|---|---|---|---|---|---|---|\n";
  // The metrics' columns, looked up once.
  const std::size_t m_err = r.metric("err"), m_trp = r.metric("trace_p"), m_gam = r.metric("gamma"), m_failed = r.metric("failed");
  const char* const counters[] = {"sent", "lost", "late", "refused"};
  std::size_t m_counter[std::size(counters)];
  for (std::size_t c = 0; c < std::size(counters); ++c) m_counter[c] = r.metric(counters[c]);
  const std::string link_name = spec.config.at("link").get<std::string>();
  for (std::size_t a = 0; a < na; ++a) {
    const std::string& nm = spec.approaches[a];
    std::vector<double> err, trp, gam;
    double failed = 0;
    double counted[std::size(counters)] = {};
    for (std::size_t x = 0; x < ns; ++x) {
      const auto add = [&](std::vector<double>& to, std::size_t m) {
        const std::vector<double> v = dropping::cell(r, a, x, m);
        to.insert(to.end(), v.begin(), v.end());
      };
      add(err, m_err);
      add(trp, m_trp);
      add(gam, m_gam);
      for (std::size_t k = 0; k < spec.seeds; ++k) {
        failed += r.at(a, x, k, m_failed);
        for (std::size_t c = 0; c < std::size(counters); ++c) counted[c] += r.at(a, x, k, m_counter[c]);
      }
    }
    nlohmann::json link = nlohmann::json::object();
    for (std::size_t c = 0; c < std::size(counters); ++c) link[counters[c]] = counted[c];
    link["delivered"] = counted[0] - counted[1];
    j["links"][nm][link_name] = link;
    const std::string kind = spec.config.at("approaches")[a].at("kind").get<std::string>();
    j["approaches"][nm] = {{"kind", kind},
                           {"cost_mean", dropping::num(sm.value[a].mean)},
                           {"cost_ci95", dropping::num(sm.value[a].ci95)},
                           {"ratio_to_" + ref, dropping::num(sm.ratio_of_means[a])},
                           {"ratio_mean", dropping::num(sm.ratio[a].mean)},
                           {"ratio_ci95", dropping::num(sm.ratio[a].ci95)},
                           {"err_mean", dropping::num(drop_mean(err))},
                           {"trace_p_mean", dropping::num(drop_mean(trp))},
                           {"gamma_mean", dropping::num(drop_mean(gam))},
                           {"failed_runs", failed}};
    md << "| " << nm << " | " << kind << " | " << md_cell(sm.value[a].mean, "%.6g") << " | ± " << md_cell(sm.value[a].ci95, "%.3g") << " | "
       << md_cell(sm.ratio_of_means[a], "%.4f") << " ± " << md_cell(sm.ratio[a].ci95, "%.4f") << " | " << md_cell(drop_mean(err), "%.6g")
       << " | " << md_cell(drop_mean(trp), "%.6g") << " | " << md_cell(drop_mean(gam), "%.4f") << " | " << failed << " |\n";
  }
  engine::add_order_by_mean(j, r, sm);
  if (!sm.paired.empty()) j["paired_differences"] = engine::paired_differences_json(r, sm);
  add_per_scenario_costs(j, md, r, sm);
  j["markdown"] = md.str();
  engine::write_runs_csv(r, util::path_in(out_dir, "runs.csv"), util::NonFinite::kMissing);
  j["files"] = {"runs.csv"};
  return j;
}

}  // namespace oneshot::study
