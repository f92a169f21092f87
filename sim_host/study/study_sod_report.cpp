/// @file study_sod_report.cpp
/// @brief `study report` and `study bench` of a "study": "sod" file (see study_sod_runner.hpp):
///        the cost plot, the traced runs, the report's markdown, the timed sweep.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <iostream>
#include <sstream>
#include <thread>

#include <nlohmann/json.hpp>

#include "oneshot/engine/study_file.hpp"
#include "oneshot/engine/sweep_statistics.hpp"
#include "oneshot/util/number_text.hpp"
#include "oneshot/util/output_files.hpp"
#include "study_bench.hpp"
#include "study_check.hpp"
#include "study_file_report.hpp"
#include "study_sod_runner.hpp"
#include "study_sod_study.hpp"
#include "study_text.hpp"

namespace oneshot::study {
namespace {

/// Traces longer than this many steps keep every ⌈steps / this⌉-th step.
constexpr std::size_t kMaxSodTraceRows = 5000;

/// OUT/table_summary.csv and, with `plots`, table.png: one bar per approach at its mean cost
/// e1 + e2 (over seeds of the scenario mean) with its 95 % interval. Returns the files.
nlohmann::json write_sod_cost_plot(const engine::SweepResults& r, const std::string& out_dir, bool plots) {
  const engine::SweepSummary sm = engine::summarize_metric(r, r.metric("cost"), 0);
  std::vector<std::vector<double>> rows;
  double lo = HUGE_VAL, hi = 0;
  for (std::size_t a = 0; a < r.spec.approaches.size(); ++a) {
    rows.push_back({static_cast<double>(a), sm.value[a].mean, sm.value[a].ci95, sm.ratio[a].mean, sm.ratio[a].ci95});
    if (std::isfinite(sm.value[a].mean) && sm.value[a].mean > 0) {
      lo = std::min(lo, sm.value[a].mean);
      hi = std::max(hi, sm.value[a].mean);
    }
  }
  util::write_csv(util::path_in(out_dir, "table_summary.csv"), {"approach_index", "mean", "ci95", "ratio_mean", "ratio_ci95"}, rows,
                  util::NonFinite::kMissing);
  nlohmann::json files = {"table_summary.csv"};
  if (!plots) return files;
  std::ostringstream tics;
  for (std::size_t a = 0; a < r.spec.approaches.size(); ++a) tics << (a ? ", " : "") << util::gnuplot_quote(r.spec.approaches[a]) << " " << a;
  std::ostringstream g;
  g << util::gnuplot_png_terminal(1100, 700) << "set output 'table.png'\n"
    << "set datafile separator ','\nset datafile missing 'nan'\nset grid ytics\nset style fill solid 0.6\nset boxwidth 0.6\nset key off\n"
    << "set xtics (" << tics.str() << ")\nset xrange [-0.6:" << static_cast<double>(r.spec.approaches.size()) - 0.4 << "]\n"
    << (hi > 100 * lo ? "set logscale y\n" : "set yrange [0:*]\n") << "set ylabel "
    << util::gnuplot_quote("e1 + e2 (mean over scenarios, 95 % CI over " + std::to_string(r.spec.seeds) + " seeds)")
    << "\nplot 'table_summary.csv' using 1:2 skip 1 with boxes lc rgb '#4c72b0', '' using 1:2:3 skip 1 with yerrorbars pt 0 lw 2 "
       "lc rgb 'black'\n";
  util::run_gnuplot(out_dir, "table.gp", g.str());
  files.push_back("table.png");
  return files;
}

/// One traced run per approach of `selected` (first scenario, first seed, the sweep's designs):
/// OUT/trace_<i>_<A>.csv (k, t_s, then per node i: x_i, xhat_i, y_i, z_i (the value the filter
/// used, empty: none), sent_i (node::SendCause: 0 none, 1 first, 2 periodic, 3 delta, 4 time), arrived_i)
/// and with `plots` its png. Returns per approach its files, e1 + e2 of the run and the step.
nlohmann::json write_sod_traces(const SodStudy& s, const SodDesigns& d, const std::vector<std::size_t>& selected,
                                const std::string& out_dir, bool plots) {
  nlohmann::json j = nlohmann::json::object();
  if (s.scenarios.empty()) return j;
  for (std::size_t a : selected) {
    const sod::RunConfig c = sod_run_config(s, d, a, 0);
    sod::RunTrace t;
    const sod::RunResult m = sod::simulate_run(s.model, c, s.first_seed, &t);
    const std::size_t step = (static_cast<std::size_t>(c.steps) + kMaxSodTraceRows - 1) / kMaxSodTraceRows;
    std::vector<std::vector<double>> rows;
    for (std::size_t k = 0; k < t.t_s.size(); k += step) {
      std::vector<double> row{static_cast<double>(k), t.t_s[k]};
      for (std::size_t i = 0; i < sod::kNodes; ++i)
        row.insert(row.end(), {t.x[i][k], t.x_hat[i][k], t.y[i][k], t.z[i][k], static_cast<double>(t.cause[i][k]),
                               static_cast<double>(t.arrived[i][k])});
      rows.push_back(row);
    }
    const std::string stem = trace_stem(a, s.approaches[a].name);
    util::write_csv(util::path_in(out_dir, stem + ".csv"),
                    {"k", "t_s", "x1", "xhat1", "y1", "z1", "sent1", "arrived1", "x2", "xhat2", "y2", "z2", "sent2", "arrived2"}, rows,
                    util::NonFinite::kMissing);
    nlohmann::json e = {{"scenario", s.scenarios[0].name}, {"seed", s.first_seed}, {"cost", finite_or_null(m.e[0] + m.e[1])}, {"every_steps", step},
                        {"files", {stem + ".csv"}}};
    if (plots) {
      const std::string csv = util::gnuplot_quote(stem + ".csv");
      std::ostringstream g;
      g << util::gnuplot_png_terminal(1100, 800, 10) << "set output " << util::gnuplot_quote(stem + ".png") << "\n"
        << "set datafile separator ','\nset datafile missing 'nan'\nset grid\nset key outside right\nset lmargin 10\nset rmargin 24\n"
        << "set multiplot layout 2,1 title "
        << util::gnuplot_quote(s.approaches[a].name + " on " + s.scenarios[0].name + ", seed " + std::to_string(s.first_seed)) << "\n";
      for (int i = 0; i < 2; ++i) {
        const int base = 3 + 6 * i;
        g << (i == 1 ? "set xlabel 't (s)'\n" : "") << "set ylabel 'x" << i + 1 << "'\nplot " << csv << " using 2:" << base
          << " skip 1 with lines lw 1.2 lc rgb '#000000' title 'x', '' using 2:" << base + 1
          << " skip 1 with lines lw 1.2 lc rgb '#c44e52' title 'xhat', '' using 2:($" << base + 5 << " > 0 ? $" << base + 3
          << " : 1/0) skip 1 with points pt 7 ps 0.3 lc rgb '#4c72b0' title 'z arrived'\n";
      }
      g << "unset multiplot\n";
      util::run_gnuplot(out_dir, stem + ".gp", g.str());
      e["files"].push_back(stem + ".png");
    }
    j[s.approaches[a].name] = e;
  }
  return j;
}

/// The report's markdown.
std::string sod_report_markdown(const SodStudy& s, const std::string& file, const std::string& resolution_text,
                                const engine::SweepResults& r, const nlohmann::json& outputs, bool plots, const nlohmann::json& traces) {
  const engine::SweepSpec& spec = r.spec;
  std::ostringstream md;
  md << "## Study file `" << std::filesystem::path(file).filename().string() << "`\n\n"
     << "`oneshot-sim study report " << file << "`: send-on-delta estimation, " << spec.approaches.size() << " approaches x "
     << spec.scenarios.size() << " scenarios x " << spec.seeds << " seeds (first seed " << spec.first_seed
     << "), the same plant, measurement and loss draws for every approach (common random numbers).\n\n"
     << "### Configuration\n\nAs `oneshot-sim study check` resolves it:\n\n```text\n" << resolution_text << "```\n\nSimulated time per run:";
  for (std::size_t x = 0; x < s.scenarios.size(); ++x)
    md << (x == 0 ? " " : ", ") << s.scenarios[x].name << " " << static_cast<double>(s.scenarios[x].steps) * s.model.period_s() << " s ("
       << s.scenarios[x].steps << " steps, xi " << s.scenarios[x].loss << ", step input " << s.scenarios[x].amplitude << ")";
  md << ".\n\n### Estimation error\n\nCost: e1 + e2, e_i = (1/N) sum_k (x_k,i - xhat_k,i)^2 of a run, per seed averaged over the "
        "scenarios; 95 % intervals over the seeds; the ratio to "
     << spec.approaches[0] << " per seed (paired). NEES: (1/N) sum_k e_k' P_k^-1 e_k (2 when the filter is consistent). "
        "Packets: per run and node.\n\n"
     << outputs.at("markdown").get<std::string>() << "\nOrder by mean cost (measured): " << outputs.at("order_text").get<std::string>() << "\n\n";
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
  if (plots) md << "![mean e1 + e2 per approach, 95 % intervals](table.png)\n\n";
  md << "### Links\n\nTotals over every run: sent (packets the node's rule sent), delivered, lost (Bernoulli xi), time rule "
        "(msod's (2b) sends), detected (losses the receiver's detector proved).\n\n"
        "| approach | link | sent | delivered | lost | time rule | detected |\n|---|---|---|---|---|---|---|\n";
  for (const std::string& a : spec.approaches)
    for (const auto& [link, e] : outputs.at("links").at(a).items()) {
      md << "| " << a << " | " << link << " |";
      for (const char* c : {"sent", "delivered", "lost", "time_rule_sent", "detected"}) md << " " << md_cell(e.at(c), "%.0f") << " |";
      md << "\n";
    }
  if (!traces.empty()) {
    md << "\n### Traces\n\nOne run per approach on the first scenario and the first seed (the sweep's run). "
       << (plots ? "Each plot: per state the true x, the estimate xhat and the values that arrived." : "CSV files only (--no-plots).")
       << "\n\n";
    for (std::size_t a = 0; a < spec.approaches.size(); ++a) {
      const std::string& an = spec.approaches[a];
      if (!traces.contains(an)) continue;
      const nlohmann::json& e = traces.at(an);
      md << "- " << an << " on " << e.at("scenario").get<std::string>() << ": e1 + e2 " << md_cell(e.at("cost"), "%.6g")
         << " (the sweep's run: " << md_cell(r.at(a, 0, 0, r.metric("cost")), "%.6g") << "); files:";
      for (const auto& f : e.at("files")) md << " `" << f.get<std::string>() << "`";
      md << "\n";
      if (plots) md << "\n![" << an << "](" << e.at("files").back().get<std::string>() << ")\n\n";
    }
  }
  return md.str();
}

}  // namespace

void report_sod_file(const SodStudy& s, const std::string& file, nlohmann::json resolution, const std::string& out, std::size_t seeds,
                     unsigned threads, bool plots, bool max_duration, const std::string* trace) {
  if (max_duration) throw engine::InputError("field '--max-duration': a sod file's runs take its duration_s");
  if (trace != nullptr && trace->empty()) throw engine::InputError("field '--trace': an empty approach name");
  std::vector<std::string> names;
  for (const SodApproach& a : s.approaches) names.push_back(a.name);
  const std::vector<std::size_t> traced = trace_selection(names, s.source, trace == nullptr ? std::string() : *trace);
  util::make_directory(out);
  const engine::SweepResults r = run_sod_sweep(s, seeds, threads, engine::Shard{});
  nlohmann::json j = sod_run_outputs(r, out, plots);
  for (const auto& f : write_sod_cost_plot(r, out, plots)) j["files"].push_back(f);
  const SodDesigns d = sod_designs(s, r.spec.seeds, threads);
  nlohmann::json traces = write_sod_traces(s, d, traced, out, plots);
  mark_same_cost_as_sweep(traces, r, traced);
  j["traces"] = traces;
  resolution["seeds"]["count"] = r.spec.seeds;  // the grid that ran: --seeds overrides the file's count
  resolution["grid"]["runs"] = r.spec.runs();
  resolution["sod"]["designs"] = d.json;
  resolution["sod"]["n_t"]["seeds"] = r.spec.seeds;
  if (s.n_t_given) resolution["sod"]["n_t"].erase("seeds");
  const std::string md = sod_report_markdown(s, file, describe_resolution(resolution) + describe_sod(resolution), r, j, plots, traces);
  util::write_text((std::filesystem::path(out) / "report.md").string(), md);
  util::write_json((std::filesystem::path(out) / "report.json").string(), j);
  std::cout << "study report: " << r.spec.runs() << " runs, written to " << (std::filesystem::path(out) / "report.md").string() << "\n";
}

nlohmann::json sod_bench(const SodStudy& s, std::size_t seeds, unsigned threads) {
  engine::SweepSpec spec = sod_sweep_spec(s, seeds, "bench-sod");
  spec.config = {{"study_file", s.source}};
  const unsigned used = threads == 0 ? std::max(1U, std::thread::hardware_concurrency()) : threads;
  const SodDesigns d = sod_designs(s, spec.seeds, used);  // before the clock: the design is not the sweep
  const double period_s = s.model.period_s();
  return timed_bench(
      spec, used, s.source,
      [&s, &d, period_s](std::size_t a, std::size_t x, std::uint64_t seed) {
        const sod::RunConfig c = sod_run_config(s, d, a, x);
        const sod::RunResult m = sod::simulate_run(s.model, c, seed);
        return BenchRun{m.e[0] + m.e[1], m.events, static_cast<double>(c.steps) * period_s};
      },
      "study bench (sod)");
}

}  // namespace oneshot::study
