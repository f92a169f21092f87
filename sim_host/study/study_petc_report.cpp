/// @file study_petc_report.cpp
/// @brief `study report` of a petc file: the GPI plot and the report's markdown (see
///        study_petc_study.hpp).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "oneshot/engine/sweep_statistics.hpp"
#include "oneshot/util/number_text.hpp"
#include "oneshot/util/output_files.hpp"
#include "study_petc_study.hpp"

namespace oneshot::study {
namespace {

/// `v` in `format`, "—" when null or not finite.
std::string petc_cell_text(const nlohmann::json& v, const char* format) {
  if (!v.is_number() || !std::isfinite(v.get<double>())) return "—";
  char b[48];
  std::snprintf(b, sizeof b, format, v.get<double>());
  return b;
}

}  // namespace

nlohmann::json write_petc_cost_plot(const engine::SweepResults& r, const std::string& out_dir, bool plots) {
  const engine::SweepSummary sm = engine::summarize_metric(r, r.metric("cost"), 0);
  const std::size_t na = r.spec.approaches.size();
  std::vector<std::vector<double>> rows;
  double top = 0;  // the highest interval's end
  for (std::size_t a = 0; a < na; ++a) {
    rows.push_back({static_cast<double>(a), sm.value[a].mean, sm.value[a].ci95, sm.ratio[a].mean, sm.ratio[a].ci95});
    if (std::isfinite(sm.value[a].mean) && std::isfinite(sm.value[a].ci95)) top = std::max(top, sm.value[a].mean + sm.value[a].ci95);
  }
  util::write_csv(util::path_in(out_dir, "table_summary.csv"), {"approach_index", "mean", "ci95", "ratio_mean", "ratio_ci95"}, rows,
                  util::NonFinite::kMissing);
  nlohmann::json files = {"table_summary.csv"};
  if (!plots) return files;
  std::ostringstream tics;
  for (std::size_t a = 0; a < na; ++a) tics << (a ? ", " : "") << util::gnuplot_quote(r.spec.approaches[a]) << " " << a;
  std::ostringstream g;
  g << util::gnuplot_png_terminal(1100, 700) << "set output 'table.png'\n"
    << "set datafile separator ','\nset datafile missing 'nan'\nset grid ytics\nset style fill solid 0.6\nset boxwidth 0.6\nset key off\n"
    << "set xtics (" << tics.str() << ")\nset xrange [-0.6:" << static_cast<double>(na) - 0.4 << "]\n"
    << (top > 0 ? "set yrange [0:" + util::format_g(1.05 * top, 6) + "]\n" : std::string("set yrange [0:*]\n")) << "set ylabel "
    << util::gnuplot_quote("GPI = 0.45 U_c + 0.45 U_a + 0.1 N_E (mean over scenarios, 95 % CI over " + std::to_string(r.spec.seeds) +
                           " seeds)")
    << "\nplot 'table_summary.csv' using 1:2 skip 1 with boxes lc rgb '#4c72b0', '' using 1:2:3 skip 1 with yerrorbars pt 0 lw 2 "
       "lc rgb 'black'\n";
  util::run_gnuplot(out_dir, "table.gp", g.str());
  files.push_back("table.png");
  return files;
}

std::string petc_report_markdown(const PetcStudy& s, const std::string& file, const std::string& resolution_text,
                                 const engine::SweepResults& r, const nlohmann::json& j, const std::string& plot_path) {
  const engine::SweepSpec& spec = r.spec;
  std::ostringstream md;
  md << "# Study file " << file << " (study petc)\n\n"
     << spec.approaches.size() << " approaches x " << spec.scenarios.size() << " scenarios x " << spec.seeds
     << " seeds (first seed " << spec.first_seed << "): " << spec.runs() << " runs.\n\n```\n" << resolution_text << "```\n\n";
  md << "Simulated time per run:";
  for (std::size_t x = 0; x < s.scenarios.size(); ++x) {
    const sim::petc::PetcSetup& st = s.setups[x];
    md << (x == 0 ? " " : ", ") << s.scenarios[x] << " " << st.opt.steps << " periods of " << st.plant.file.period_us << " us";
  }
  md << ".\n\n## GPI (the cost) per approach\n\nGPI = 0.45 U_c + 0.45 U_a + 0.1 N_E (U_c, U_a: the sensor's and the "
        "controller's sends per period; N_E = ISEP / ISE of the TTS response), mean over seeds of the scenario mean, 95 % "
        "intervals; ratios to "
     << spec.approaches[0] << ".\n\n"
     << j.at("markdown").get<std::string>() << "\nOrder by mean GPI: " << j.at("order_text").get<std::string>() << "\n\n";
  if (j.contains("paired_differences")) {
    md << "Paired differences of the GPI (A - B per seed, mean and 95 % interval):\n\n| pair | mean | 95 % CI |\n|---|---|---|\n";
    for (const auto& [pair, p] : j.at("paired_differences").items())
      md << "| " << pair << " | " << petc_cell_text(p.at("mean"), "%.6g") << " | ± " << petc_cell_text(p.at("ci95"), "%.3g") << " |\n";
    md << "\n";
  }
  if (!plot_path.empty()) md << "![GPI](" << plot_path << ")\n\n";
  md << "## The petc table's columns per approach\n\n| approach | longest silence s / a | safety s / c | N_max | multiply-adds / "
        "run | max per arrival | ISEP | rms d |\n|---|---|---|---|---|---|---|---|\n";
  for (const std::string& a : spec.approaches) {
    const nlohmann::json& m = j.at("approaches").at(a).at("metrics");
    const auto mean = [&](const char* k, const char* f = "%.4g") { return petc_cell_text(m.at(k).at("mean"), f); };
    md << "| " << a << " | " << mean("longest_silence_sensor") << " / " << mean("longest_silence_actuator") << " | "
       << mean("sensor_safety_fires") << " / " << mean("controller_safety_fires") << " | " << mean("N_max") << " | " << mean("macs")
       << " | " << mean("macs_max_arrival") << " | " << mean("ISEP") << " | " << mean("d_rms") << " |\n";
  }
  md << "\n## Links\n\nZero delay, no loss: every frame sent is delivered.\n\n| approach | link | sent | delivered |\n|---|---|---|---|\n";
  for (const std::string& a : spec.approaches)
    for (const auto& [link, c] : j.at("links").at(a).items())
      md << "| " << a << " | " << link << " | " << petc_cell_text(c.at("sent"), "%.0f") << " | "
         << petc_cell_text(c.at("delivered"), "%.0f") << " |\n";
  md << "\nNo traces: `oneshot-sim petc traces` draws d, d_hat and N of the built-in cases.\n";
  return md.str();
}

}  // namespace oneshot::study
