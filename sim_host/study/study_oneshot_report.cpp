/// @file study_oneshot_report.cpp
/// @brief `oneshot-sim study report FILE OUTDIR` of a "study": "oneshot" file (see
///        study_oneshot_study.hpp): the sweep, the cost plot and the report's markdown.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>

#include "oneshot/engine/sweep.hpp"
#include "oneshot/util/output_files.hpp"
#include "study_dropping_report.hpp"
#include "study_oneshot_study.hpp"

namespace oneshot::study {
namespace {

/// `v` in `format`, "—" when null or not finite.
std::string os_cell(const nlohmann::json& v, const char* format) {
  if (!v.is_number() || !std::isfinite(v.get<double>())) return "—";
  char b[48];
  std::snprintf(b, sizeof b, format, v.get<double>());
  return b;
}

}  // namespace

void oneshot_report_command(const OneShotFileStudy& s, const std::string& file, const std::string& resolution_text,
                            std::size_t seeds, unsigned threads, const std::string& out, bool plots) {
  util::make_directory(out);
  const engine::SweepResults r = run_oneshot_sweep(s, seeds, threads, engine::Shard{});
  nlohmann::json j = oneshot_run_outputs(r, out, false);
  // The cost plot: one bar per approach at its mean over every run, its 95 % interval (the
  // dropping report's plot: it reads the sweep's "cost" only).
  for (const auto& f : write_dropping_cost_plot(r, out, plots)) j["files"].push_back(f);
  const engine::SweepSpec& spec = r.spec;
  std::ostringstream md;
  double simulated = 0;
  for (const sim::Scenario& x : s.scenarios) simulated += x.duration_s;
  md << "# Study report: " << file << "\n\n## Configuration\n\n```\n" << resolution_text << "```\n\n"
     << "Grid: " << spec.approaches.size() << " approaches x " << spec.scenarios.size() << " scenarios x " << spec.seeds
     << " seeds = " << spec.runs() << " runs (first seed " << spec.first_seed << "), " << simulated * static_cast<double>(spec.approaches.size() * spec.seeds)
     << " s simulated. Each run is `oneshot-sim oneshot table1`'s run of the approach on the scenario and seed (sim::simulate: "
        "the emulated board, PWM and 12-bit ADC, the firmware's control job).\n\n"
     << "## Results\n\nMean cost J over every scenario and seed with its 95 % interval; the ratio to " << spec.approaches[0]
     << " per seed (paired), its mean's ratio beside; saturated runs: the fixed-point flag raised; overruns: actuation instants "
        "without a prepared value. Per scenario: the mean cost.\n\n"
     << j.at("markdown").get<std::string>() << "\nOrder by mean cost (measured): " << j.at("order_text").get<std::string>() << "\n\n";
  if (j.contains("paired_differences")) {
    md << "Paired differences of the mean cost (per seed, 95 % CI):\n\n| pair | mean | 95 % CI |\n|---|---|---|\n";
    for (std::size_t a = 0; a < spec.approaches.size(); ++a)
      for (std::size_t b = a + 1; b < spec.approaches.size(); ++b) {
        const std::string key = spec.approaches[a] + "-" + spec.approaches[b];
        const nlohmann::json& p = j.at("paired_differences").at(key);
        md << "| " << key << " | " << os_cell(p.at("mean"), "%.6g") << " | ± " << os_cell(p.at("ci95"), "%.3g") << " |\n";
      }
    md << "\n";
  }
  if (plots) md << "![mean cost per approach, 95 % intervals](table.png)\n\n";
  md << "No traced runs: `oneshot-sim oneshot run` traces one run of the board (jobs and a dense state trace).\n";
  util::write_text((std::filesystem::path(out) / "report.md").string(), md.str());
  util::write_json((std::filesystem::path(out) / "report.json").string(), j);
  std::cout << "study report: " << r.spec.runs() << " runs, written to " << (std::filesystem::path(out) / "report.md").string() << "\n";
}

}  // namespace oneshot::study
