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
#include "study_text.hpp"

namespace oneshot::study {
namespace {

/// The gnuplot script of one traced run (see write_petc_traces()).
std::string petc_trace_plot(const std::string& stem, const std::string& title) {
  const std::string csv = util::gnuplot_quote(stem + ".csv");
  std::ostringstream g;
  g << util::gnuplot_png_terminal(1100, 950, 10) << "set output " << util::gnuplot_quote(stem + ".png") << "\n"
    << "set datafile separator ','\nset grid\nset key outside right\nset lmargin 12\nset rmargin 24\n"
    << "set multiplot layout 3,1 title " << util::gnuplot_quote(title) << "\n"
    << "set ylabel 'output'\nplot " << csv << " using 2:4 skip 1 with lines lw 1.2 lc rgb '#000000' title 'y', '' using "
       "2:($9 > 0 ? $5 : 1/0) skip 1 with points pt 7 ps 0.35 lc rgb '#8888cc' title 'y sent', '' using 2:3 skip 1 with lines "
       "dt 2 lc rgb 'gray' title 'r'\n"
    << "set ylabel 'u'\nplot " << csv << " using 2:6 skip 1 with steps lc rgb '#000000' title 'u applied', '' using 2:($10 > 0 ? "
       "$6 : 1/0) skip 1 with points pt 7 ps 0.35 lc rgb '#c44e52' title 'packet sent'\n"
    << "set xlabel 't (s)'\nset ylabel 'disturbance'\nplot " << csv << " using 2:7 skip 1 with lines lc rgb '#4c72b0' title "
       "'d', '' using 2:8 skip 1 with lines lc rgb '#c44e52' title 'd hat'\nunset multiplot\n";
  return g.str();
}

}  // namespace

nlohmann::json write_petc_traces(const PetcStudy& s, const std::vector<std::size_t>& selected, const std::string& out_dir,
                                 bool plots) {
  nlohmann::json j = nlohmann::json::object();
  if (s.scenarios.empty()) return j;
  const sim::petc::PetcSetup& st = s.setups[0];
  const double period_s = static_cast<double>(st.plant.file.period_us) * 1e-6;
  for (std::size_t a : selected) {
    sim::petc::RunTrace t;
    const std::vector<double> v = sim::petc::run_case(st, s.runs[a][0], s.first_seed, &t);
    std::vector<std::vector<double>> rows;
    for (std::size_t k = 0; k < t.y_true.size() && k < t.u.size() && k < t.d.size(); ++k)
      rows.push_back({static_cast<double>(k), static_cast<double>(k) * period_s, st.opt.reference, t.y_true[k], t.y_meas[k], t.u[k],
                      t.d[k], t.d_hat[k], static_cast<double>(t.sensor_sent[k]), static_cast<double>(t.actuator_sent[k])});
    const std::string stem = trace_stem(a, s.approaches[a]);
    util::write_csv(util::path_in(out_dir, stem + ".csv"),
                    {"k", "t_s", "r", "y", "y_meas", "u", "d", "d_hat", "sensor_sent", "actuator_sent"}, rows);
    nlohmann::json e = {{"scenario", s.scenarios[0]}, {"seed", s.first_seed}, {"cost", finite_or_null(v[petc_gpi_index()])}, {"files", {stem + ".csv"}}};
    if (plots) {
      const std::string title = s.approaches[a] + " (" + s.kinds[a] + ") on " + s.scenarios[0] + ", seed " +
                                std::to_string(s.first_seed) + ": output and samples, input and packets, d and d hat";
      util::run_gnuplot(out_dir, stem + ".gp", petc_trace_plot(stem, title));
      e["files"].push_back(stem + ".png");
    }
    j[s.approaches[a]] = e;
  }
  return j;
}

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
                                 const engine::SweepResults& r, const nlohmann::json& j, const std::string& plot_path,
                                 const nlohmann::json& traces, bool plots) {
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
      md << "| " << pair << " | " << md_cell(p.at("mean"), "%.6g") << " | ± " << md_cell(p.at("ci95"), "%.3g") << " |\n";
    md << "\n";
  }
  if (!plot_path.empty()) md << "![GPI](" << plot_path << ")\n\n";
  md << "## The petc table's columns per approach\n\n| approach | longest silence s / a | safety s / c | N_max | multiply-adds / "
        "run | max per arrival | ISEP | rms d |\n|---|---|---|---|---|---|---|---|\n";
  for (const std::string& a : spec.approaches) {
    const nlohmann::json& m = j.at("approaches").at(a).at("metrics");
    const auto mean = [&](const char* k, const char* f = "%.4g") { return md_cell(m.at(k).at("mean"), f); };
    md << "| " << a << " | " << mean("longest_silence_sensor") << " / " << mean("longest_silence_actuator") << " | "
       << mean("sensor_safety_fires") << " / " << mean("controller_safety_fires") << " | " << mean("N_max") << " | " << mean("macs")
       << " | " << mean("macs_max_arrival") << " | " << mean("ISEP") << " | " << mean("d_rms") << " |\n";
  }
  md << "\n## Links\n\nZero delay, no loss: every frame sent is delivered.\n\n| approach | link | sent | delivered |\n|---|---|---|---|\n";
  for (const std::string& a : spec.approaches)
    for (const auto& [link, c] : j.at("links").at(a).items())
      md << "| " << a << " | " << link << " | " << md_cell(c.at("sent"), "%.0f") << " | "
         << md_cell(c.at("delivered"), "%.0f") << " |\n";
  if (!traces.empty()) {
    md << "\n## Traces\n\nOne run per approach on the first scenario and the first seed (the sweep's run: same seed, same "
          "draws; the trace only records). "
       << (plots ? "Each plot: the output y, the samples the sensor sends and r; the applied input u and the instants the "
                   "controller sends a packet; the disturbance d and its estimate d hat (0 without an estimator)."
                 : "CSV files only (--no-plots).")
       << "\n\n";
    const std::size_t cost = r.metric("cost");
    for (std::size_t a = 0; a < spec.approaches.size(); ++a) {
      const std::string& an = spec.approaches[a];
      if (!traces.contains(an)) continue;
      const nlohmann::json& e = traces.at(an);
      char line[160];
      std::snprintf(line, sizeof line, "(the sweep's run: %.6g)", r.at(a, 0, 0, cost));
      md << "- " << an << " on " << e.at("scenario").get<std::string>() << ": GPI " << md_cell(e.at("cost"), "%.6g") << " "
         << line << "; files:";
      for (const auto& f : e.at("files")) md << " `" << f.get<std::string>() << "`";
      md << "\n";
      if (plots) md << "\n![" << an << "](" << e.at("files").back().get<std::string>() << ")\n\n";
    }
  }
  return md.str();
}

}  // namespace oneshot::study
