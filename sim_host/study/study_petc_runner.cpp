/// @file study_petc_runner.cpp
/// @brief A "study": "petc" file's sweep, its summary and its bench (see study_petc_study.hpp).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "oneshot/engine/sweep.hpp"
#include "oneshot/engine/sweep_statistics.hpp"
#include "oneshot/util/output_files.hpp"
#include "oneshot/util/statistics.hpp"
#include "petc_experiments.hpp"
#include "study_bench.hpp"
#include "study_petc_study.hpp"
#include "study_text.hpp"

namespace oneshot::study {
namespace {

namespace pt = sim::petc;

/// The sweep's configuration: what a shard must agree on (the file, the plant, per scenario the
/// design's options and digest, per approach its cases).
nlohmann::json petc_config(const PetcStudy& s) {
  nlohmann::json runs = nlohmann::json::array();
  for (std::size_t a = 0; a < s.approaches.size(); ++a) {
    nlohmann::json per = nlohmann::json::array();
    for (const pt::CaseSpec& c : s.runs[a]) per.push_back(petc_case_json(c));
    runs.push_back({{"name", s.approaches[a]}, {"kind", s.kinds[a]}, {"per_scenario", per}});
  }
  nlohmann::json setups = nlohmann::json::array();
  for (const pt::PetcSetup& x : s.setups) setups.push_back(pt::setup_config(x));
  return {{"study_file", s.source}, {"plant", s.setups.empty() ? std::string() : s.setups[0].plant.file.name},
          {"links", {{"sc", s.sc}, {"ca", s.ca}}}, {"setups", setups}, {"approaches", runs}};
}

}  // namespace

engine::SweepSpec petc_sweep_spec(const PetcStudy& s, std::size_t seeds, const char* experiment) {
  engine::SweepSpec spec;
  spec.study = "study";
  spec.experiment = experiment;
  spec.approaches = s.approaches;
  spec.scenarios = s.scenarios;
  spec.first_seed = s.first_seed;
  spec.seeds = seeds == 0 ? s.seeds : seeds;
  return spec;
}

std::size_t petc_gpi_index() {
  static const std::size_t index = [] {
    const std::vector<std::string>& names = pt::metric_names();
    const auto it = std::find(names.begin(), names.end(), "GPI");
    if (it == names.end()) throw std::logic_error("petc: no metric GPI");
    return static_cast<std::size_t>(it - names.begin());
  }();
  return index;
}

engine::SweepResults run_petc_sweep(const PetcStudy& s, std::size_t seeds, unsigned threads, const engine::Shard& shard) {
  engine::SweepSpec spec = petc_sweep_spec(s, seeds, "run-petc");
  spec.metrics = {"cost"};
  for (const std::string& m : pt::metric_names()) spec.metrics.push_back(m);
  spec.config = petc_config(s);
  const std::size_t gpi = petc_gpi_index();
  return engine::run_sweep(
      spec, shard, threads,
      [&s, gpi](std::size_t a, std::size_t x, std::uint64_t seed) {
        std::vector<double> v = pt::run_case(s.setups[x], s.runs[a][x], seed);
        v.insert(v.begin(), v[gpi]);  // cost = GPI
        return v;
      },
      "study run (petc)");
}

nlohmann::json petc_run_outputs(const engine::SweepResults& r, const std::string& out_dir, bool plots) {
  static_cast<void>(plots);  // no plot: the table and the runs' CSV (study report draws the cost plot)
  util::make_directory(out_dir);
  const engine::SweepSpec& spec = r.spec;
  const std::size_t na = spec.approaches.size(), ns = spec.scenarios.size();
  const engine::SweepSummary sm = engine::summarize_metric(r, r.metric("cost"), 0);
  std::vector<engine::SweepSummary> all;
  for (std::size_t m = 1; m < spec.metrics.size(); ++m) all.push_back(engine::summarize_metric(r, m, 0));
  const std::string ref = spec.approaches[0];
  nlohmann::json j;
  j["study"] = "petc";
  j["experiment"] = "study run";
  j["cost_metric"] = "GPI = 0.45 U_c + 0.45 U_a + 0.1 N_E";
  j["study_file"] = spec.config.at("study_file");
  j["plant"] = spec.config.at("plant");
  j["first_seed"] = spec.first_seed;
  j["seeds"] = spec.seeds;
  j["runs"] = spec.runs();
  j["settings"] = spec.config.at("approaches");
  j["setups"] = spec.config.at("setups");
  std::ostringstream md;
  md << "| approach | kind | mean GPI | 95 % CI | ratio to " << ref << " (95 % CI) | U_c | U_a | C_c | N_E | rms(d - d_hat) |\n"
     << "|---|---|---|---|---|---|---|---|---|---|\n";
  const std::string sc = spec.config.at("links").at("sc").get<std::string>();
  const std::string ca = spec.config.at("links").at("ca").get<std::string>();
  const std::size_t m_s = r.metric("sensor_packets"), m_a = r.metric("actuator_packets");
  const auto metric_mean = [&](const char* name) -> const std::vector<util::Summary>& { return all[r.metric(name) - 1].value; };
  for (std::size_t a = 0; a < na; ++a) {
    const std::string& nm = spec.approaches[a];
    double sent_s = 0, sent_a = 0;
    for (std::size_t x = 0; x < ns; ++x)
      for (std::size_t k = 0; k < spec.seeds; ++k) {
        sent_s += r.at(a, x, k, m_s);
        sent_a += r.at(a, x, k, m_a);
      }
    j["links"][nm][sc] = {{"sent", sent_s}, {"delivered", sent_s}, {"lost", 0}, {"late", 0}, {"refused", 0}};
    j["links"][nm][ca] = {{"sent", sent_a}, {"delivered", sent_a}, {"lost", 0}, {"late", 0}, {"refused", 0}};
    nlohmann::json metrics = nlohmann::json::object();
    for (std::size_t m = 1; m < spec.metrics.size(); ++m) metrics[spec.metrics[m]] = util::mean_ci_json(all[m - 1].value[a]);
    const std::string kind = spec.config.at("approaches")[a].at("kind").get<std::string>();
    j["approaches"][nm] = {{"kind", kind},
                           {"cost_mean", finite_or_null(sm.value[a].mean)},
                           {"cost_ci95", finite_or_null(sm.value[a].ci95)},
                           {"ratio_to_" + ref, finite_or_null(sm.ratio_of_means[a])},
                           {"ratio_mean", finite_or_null(sm.ratio[a].mean)},
                           {"ratio_ci95", finite_or_null(sm.ratio[a].ci95)},
                           {"metrics", metrics}};
    const auto cell = [&](const char* name) {
      const util::Summary& v = metric_mean(name)[a];
      return md_cell(v.mean, "%.4g") + " ± " + md_cell(v.ci95, "%.2g");
    };
    md << "| " << nm << " | " << kind << " | " << md_cell(sm.value[a].mean, "%.6g") << " | ± " << md_cell(sm.value[a].ci95, "%.3g")
       << " | " << md_cell(sm.ratio_of_means[a], "%.4f") << " ± " << md_cell(sm.ratio[a].ci95, "%.4f") << " | " << cell("U_c")
       << " | " << cell("U_a") << " | " << cell("C_c") << " | " << cell("N_E") << " | " << cell("d_error_rms") << " |\n";
  }
  engine::add_order_by_mean(j, r, sm);
  if (!sm.paired.empty()) j["paired_differences"] = engine::paired_differences_json(r, sm);
  add_per_scenario_costs(j, md, r, sm);
  j["markdown"] = md.str();
  engine::write_runs_csv(r, util::path_in(out_dir, "runs.csv"), util::NonFinite::kMissing);
  j["files"] = {"runs.csv"};
  return j;
}

nlohmann::json petc_bench(const PetcStudy& s, std::size_t seeds, unsigned threads) {
  engine::SweepSpec spec = petc_sweep_spec(s, seeds, "bench-petc");
  spec.config = {{"study_file", s.source}};
  return timed_bench(
      spec, threads, s.source,
      [&s](std::size_t a, std::size_t x, std::uint64_t seed) {
        pt::FaultRun clean;  // an empty spec: the clean run, bit for bit; it counts the kernel's events
        const std::vector<double> v = pt::run_case(s.setups[x], s.runs[a][x], seed, nullptr, &clean);
        const pt::PetcSetup& st = s.setups[x];
        const double simulated = static_cast<double>(st.opt.steps) * static_cast<double>(st.plant.file.period_us) * 1e-6;
        return BenchRun{v[petc_gpi_index()], static_cast<double>(clean.events), simulated};
      },
      "study bench (petc)");
}

}  // namespace oneshot::study
