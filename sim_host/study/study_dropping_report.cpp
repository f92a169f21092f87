/// @file study_dropping_report.cpp
/// @brief The report and the bench of a dropping file (see study_dropping_report.hpp).
#include "study_dropping_report.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <sstream>

#include "oneshot/engine/sweep_statistics.hpp"
#include "oneshot/util/number_text.hpp"
#include "oneshot/util/output_files.hpp"
#include "study_dropping_runner.hpp"
#include "study_dropping_study.hpp"
#include "study_format.hpp"
#include "study_text.hpp"

namespace oneshot::study {
namespace {

/// Traces longer than this many steps keep every ⌈steps / this⌉-th step.
constexpr std::size_t kMaxDropTraceRows = 5000;

/// The gnuplot script of one traced run (see write_dropping_traces()).
std::string drop_trace_plot(const std::string& stem, const std::string& title) {
  const std::string csv = util::gnuplot_quote(stem + ".csv");
  std::ostringstream g;
  g << util::gnuplot_png_terminal(1100, 950, 10) << "set output " << util::gnuplot_quote(stem + ".png") << "\n"
    << "set datafile separator ','\nset datafile missing 'nan'\nset grid\nset key outside right\nset lmargin 10\nset rmargin 24\n"
    << "set multiplot layout 3,1 title " << util::gnuplot_quote(title) << "\n"
    << "set ylabel 'output'\nplot " << csv << " using 2:5 skip 1 with lines lw 1.2 lc rgb '#000000' title 'C x', '' using 2:6 skip 1 "
    << "with lines lw 1.2 lc rgb '#c44e52' title 'C xhat', '' using 2:4 skip 1 with points pt 7 ps 0.25 lc rgb '#8888cc' title "
       "'y sent', '' using 2:3 skip 1 with lines dt 2 lc rgb 'gray' title 'r'\n"
    << "set ylabel 'u'\nplot " << csv << " using 2:7 skip 1 with steps lc rgb '#000000' title 'u applied'\n"
    << "set xlabel 't (s)'\nset ylabel 'per step'\nset logscale y\nplot " << csv
    << " using 2:8 skip 1 with lines lc rgb '#4c72b0' title 'tr P', '' using 2:($9 > 0 ? $9 : 1/0) skip 1 with lines lc rgb "
       "'#c44e52' title '|x - xhat|^2'\nunset multiplot\n";
  return g.str();
}

}  // namespace

nlohmann::json write_dropping_cost_plot(const engine::SweepResults& r, const std::string& out_dir, bool plots) {
  const engine::SweepSummary sm = engine::summarize_metric(r, r.metric("cost"), 0);
  const std::size_t na = r.spec.approaches.size();
  std::vector<std::vector<double>> rows;
  double lo = HUGE_VAL, hi = 0, top = 0;  // the smallest and largest finite means, the highest interval's end
  for (std::size_t a = 0; a < na; ++a) {
    rows.push_back({static_cast<double>(a), sm.value[a].mean, sm.value[a].ci95, sm.ratio[a].mean, sm.ratio[a].ci95});
    if (std::isfinite(sm.value[a].mean) && sm.value[a].mean > 0) {
      lo = std::min(lo, sm.value[a].mean);
      hi = std::max(hi, sm.value[a].mean);
      if (std::isfinite(sm.value[a].ci95)) top = std::max(top, sm.value[a].mean + sm.value[a].ci95);
    }
  }
  util::write_csv(util::path_in(out_dir, "table_summary.csv"), {"approach_index", "mean", "ci95", "ratio_mean", "ratio_ci95"}, rows,
                  util::NonFinite::kMissing);
  nlohmann::json files = {"table_summary.csv"};
  if (!plots) return files;
  const bool log_scale = hi > 100 * lo;  // bars of very different heights: each stays readable
  std::ostringstream tics;
  for (std::size_t a = 0; a < na; ++a) {
    const bool finite = std::isfinite(sm.value[a].mean);
    tics << (a ? ", " : "") << util::gnuplot_quote(r.spec.approaches[a] + (finite ? "" : " (not finite)")) << " " << a;
  }
  std::ostringstream g;
  g << util::gnuplot_png_terminal(1100, 700) << "set output 'table.png'\n"
    << "set datafile separator ','\nset datafile missing 'nan'\nset grid ytics\nset style fill solid 0.6\nset boxwidth 0.6\nset key off\n"
    << "set xtics (" << tics.str() << ")\nset xrange [-0.6:" << static_cast<double>(na) - 0.4 << "]\n"
    << (log_scale ? "set logscale y\n" : top > 0 ? "set yrange [0:" + util::format_g(1.05 * top, 6) + "]\n" : std::string("set yrange [0:*]\n"))
    << "set ylabel "
    << util::gnuplot_quote("cost J per step (mean over scenarios, 95 % CI over " + std::to_string(r.spec.seeds) + " seeds)")
    << "\nplot 'table_summary.csv' using 1:2 skip 1 with boxes lc rgb '#4c72b0', '' using 1:2:3 skip 1 with yerrorbars pt 0 lw 2 "
       "lc rgb 'black'\n";
  util::run_gnuplot(out_dir, "table.gp", g.str());
  files.push_back("table.png");
  return files;
}

nlohmann::json write_dropping_traces(const DroppingStudy& s, const std::vector<std::size_t>& selected, const std::string& out_dir,
                                     bool plots) {
  nlohmann::json j = nlohmann::json::object();
  if (s.scenarios.empty()) return j;
  const double period_s = static_cast<double>(s.plant.plant.period_us) * 1e-6;
  for (std::size_t a : selected) {
    dropping::RunConfig c = s.runs[a][0];
    c.trace = true;
    const dropping::RunMetrics m = dropping::run_closed_loop(s.plant, c, s.first_seed);
    const dropping::RunTrace& t = m.trace;
    const std::size_t step = (c.steps + kMaxDropTraceRows - 1) / kMaxDropTraceRows;
    std::vector<std::vector<double>> rows;
    for (std::size_t k = 0; k < t.y.size() && k < t.cxhat.size(); k += step) {
      rows.push_back({static_cast<double>(k), static_cast<double>(k) * period_s, t.r[k], t.y[k], t.cx[k], t.cxhat[k], t.u[k],
                      t.trace_p[k], t.err[k]});
    }
    const std::string stem = trace_stem(a, s.approaches[a]);
    util::write_csv(util::path_in(out_dir, stem + ".csv"), {"k", "t_s", "r", "y", "cx", "cxhat", "u", "trace_p", "err"}, rows,
                    util::NonFinite::kMissing);
    nlohmann::json e = {{"scenario", s.scenarios[0]}, {"seed", s.first_seed}, {"cost", dropping::num(m.cost)}, {"every_steps", step},
                        {"files", {stem + ".csv"}}};
    if (plots) {
      const std::string title = s.approaches[a] + " on " + s.scenarios[0] + ", seed " + std::to_string(s.first_seed) +
                                ": output, estimate, input, covariance";
      util::run_gnuplot(out_dir, stem + ".gp", drop_trace_plot(stem, title));
      e["files"].push_back(stem + ".png");
    }
    j[s.approaches[a]] = e;
  }
  return j;
}

std::string dropping_report_markdown(const DroppingStudy& s, const std::string& file, const std::string& resolution_text,
                                     const engine::SweepResults& r, const nlohmann::json& outputs, const std::string& plot_path,
                                     const nlohmann::json& traces, bool plots) {
  const engine::SweepSpec& spec = r.spec;
  const std::string ref = spec.approaches[0];
  std::ostringstream md;
  md << "## Study file `" << std::filesystem::path(file).filename().string() << "`\n\n"
     << "`oneshot-sim study report " << file << "`: the dropping loop, " << spec.approaches.size() << " approaches x "
     << spec.scenarios.size() << " scenarios x " << spec.seeds << " seeds (first seed " << spec.first_seed
     << "), the same delay, loss and noise draws for every approach (common random numbers).\n\n"
     << "### Configuration\n\nAs `oneshot-sim study check` resolves it:\n\n```text\n" << resolution_text << "```\n\n"
     << "Simulated time per run:";
  for (std::size_t x = 0; x < s.scenarios.size(); ++x) {
    const std::size_t steps = s.runs[0][x].steps;
    md << (x == 0 ? " " : ", ") << s.scenarios[x] << " " << static_cast<double>(steps) * s.plant.plant.period_us * 1e-6 << " s ("
       << steps << " steps)";
  }
  md << ".\n\n### Cost\n\nJ: the plant's cost per step, (1/N) sum_k x_k' Q1 x_k + u_k' Q2 u_k, per seed averaged over the "
        "scenarios; 95 % intervals over the seeds; the ratio to "
     << ref << " per seed (paired), its mean's ratio beside. |x - xhat|^2, tr P: the loop estimate's squared error and the "
        "filter's covariance per step; gamma: the buffered filter's arrival fraction at its anchor; failed: runs whose filter "
        "reported a failure. \"—\": not finite (a diverged loop). Per scenario: the mean cost.\n\n"
     << outputs.at("markdown").get<std::string>() << "\nOrder by mean cost (measured): " << outputs.at("order_text").get<std::string>()
     << "\n\n";
  if (outputs.contains("paired_differences")) {
    md << "Paired differences of the mean cost (per seed, 95 % CI):\n\n| pair | mean | 95 % CI |\n|---|---|---|\n";
    for (std::size_t a = 0; a < spec.approaches.size(); ++a)
      for (std::size_t b = a + 1; b < spec.approaches.size(); ++b) {
        const std::string key = spec.approaches[a] + "-" + spec.approaches[b];
        const nlohmann::json& p = outputs.at("paired_differences").at(key);
        md << "| " << key << " | " << md_cell(p.at("mean"), "%.6g") << " | ± " << md_cell(p.at("ci95"), "%.3g") << " |\n";
      }
    md << "\n";
  }
  if (!plot_path.empty()) md << "![mean cost per approach, 95 % intervals](" << plot_path << ")\n\n";
  md << "### Estimator\n\nPer approach over every run: the mean squared error of the loop estimate E|x - xhat|^2 and the "
        "filter's mean tr P (each over the runs where it is finite), whose ratio is 1 when P is the covariance of the "
        "estimate's error (a consistent filter; above 1: the filter trusts itself too much), given only when every run of "
        "the approach is finite (both means then over the same runs); gamma, the fraction of the buffered filter's anchor steps with the measurement "
        "in its buffer. The plant's lambda_sys and the bracket of lambda_c are in the configuration above.\n\n"
     << "| approach | E|x - xhat|^2 | E tr P | ratio | gamma |\n|---|---|---|---|---|\n";
  for (const std::string& a : spec.approaches) {
    const nlohmann::json& e = outputs.at("approaches").at(a);
    const nlohmann::json& err = e.at("err_mean");
    const nlohmann::json& trp = e.at("trace_p_mean");
    // The ratio only when both means cover the same runs: every run finite (the cost mean is
    // then a number; the means skip a diverged run's non-finite values, each on its own).
    const nlohmann::json ratio = e.at("cost_mean").is_number() && err.is_number() && trp.is_number() && trp.get<double>() > 0
                                     ? nlohmann::json(err.get<double>() / trp.get<double>())
                                     : nlohmann::json(nullptr);
    md << "| " << a << " | " << md_cell(err, "%.6g") << " | " << md_cell(trp, "%.6g") << " | " << md_cell(ratio, "%.4g")
       << " | " << md_cell(e.at("gamma_mean"), "%.4f") << " |\n";
  }
  const std::string link = spec.config.at("link").get<std::string>();
  md << "\n### Links\n\nTotals over every run of the link `" << link
     << "` (sensor to controller): sent (samples handed to it; on the Bernoulli channel one per step), delivered (not lost), "
        "lost (by the loss model, or gamma_k = 0 on the Bernoulli channel), late (the buffered filter's over-delayed "
        "samples, the unaware KF's stale ones: not newer than the period's newest), refused (by the controller's frame "
        "checks).\n\n| approach | link | sent | delivered | lost | late | refused |\n|---|---|---|---|---|---|---|\n";
  for (const std::string& a : spec.approaches) {
    const nlohmann::json& e = outputs.at("links").at(a).at(link);
    md << "| " << a << " | " << link << " |";
    for (const char* c : {"sent", "delivered", "lost", "late", "refused"}) {
      char v[32];
      std::snprintf(v, sizeof v, " %.0f |", e.at(c).get<double>());
      md << v;
    }
    md << "\n";
  }
  if (!traces.empty()) {
    md << "\n### Traces\n\nOne run per approach on the first scenario and the first seed (the sweep's run: same seed, same "
          "draws; the trace only observes). "
       << (plots ? "Each plot: the output C x, the loop estimate C xhat, the samples y the sensor sends and the square wave "
                   "r; the applied input u; tr P and the squared error per step (log scale). The loop records per step: no "
                   "message arrows (the counts are in the links table)."
                 : "CSV files only (--no-plots).")
       << "\n\n";
    const std::size_t cost = r.metric("cost");
    for (std::size_t a = 0; a < spec.approaches.size(); ++a) {
      const std::string& an = spec.approaches[a];
      if (!traces.contains(an)) continue;
      const nlohmann::json& e = traces.at(an);
      char line[160];
      std::snprintf(line, sizeof line, "(the sweep's run: %.6g)", r.at(a, 0, 0, cost));
      md << "- " << an << " on " << e.at("scenario").get<std::string>() << ": cost " << md_cell(e.at("cost"), "%.6g") << " "
         << line << "; files:";
      for (const auto& f : e.at("files")) md << " `" << f.get<std::string>() << "`";
      md << "\n";
      if (plots) md << "\n![" << an << "](" << e.at("files").back().get<std::string>() << ")\n\n";
    }
  }
  return md.str();
}

}  // namespace oneshot::study
