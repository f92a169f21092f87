/// @file ncs_traces.cpp
/// @brief E1–E3 of study `ncs`: single runs traced every millisecond, written as CSV and
///        drawn by gnuplot (the brief's Figs. 6–8).
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "ncs_experiments.hpp"
#include "ncs_loop.hpp"
#include "oneshot/util/output_files.hpp"

namespace oneshot::ncs {
namespace {

constexpr double kTraceStep = 1e-3;

using util::path_in;

Scenario pick(const char* scenario_name, double duration_s) {
  for (Scenario s : default_scenarios()) {
    if (s.name == scenario_name) {
      s.duration_s = duration_s;
      return s;
    }
  }
  throw std::logic_error("ncs: no scenario " + std::string(scenario_name));
}

/// True state at t from a trace recorded every kTraceStep from 0.
const Point& truth_at(const RunResult& r, double t) {
  const auto i = static_cast<std::size_t>(std::llround(t / kTraceStep));
  if (i >= r.truth.size()) throw std::logic_error("ncs: trace too short");
  return r.truth[i];
}

/// Traces of x1 of several runs side by side with the set-point: t, x1 per run, r.
void write_x1(const std::string& path, const std::vector<const RunResult*>& runs, const std::vector<std::string>& names) {
  std::vector<std::string> header{"t_s"};
  for (const auto& n : names) header.push_back("x1_" + n);
  header.emplace_back("r");
  std::vector<std::vector<double>> rows;
  for (std::size_t i = 0; i < runs[0]->truth.size(); ++i) {
    std::vector<double> row{runs[0]->truth[i].t_s};
    for (const RunResult* r : runs) row.push_back(r->truth[i].v[0]);
    row.push_back(runs[0]->setpoint[i].v[0]);
    rows.push_back(row);
  }
  util::write_csv(path, header, rows);
}

std::string x1_plot(const std::string& png, const std::string& csv, const std::string& title,
                    const std::vector<std::string>& names) {
  std::ostringstream g;
  g << util::gnuplot_png_terminal(1100, 600) << "set output '" << png
    << "'\nset datafile separator ','\nset grid\nset key outside right\nset xlabel 't (s)'\nset ylabel 'v1 (V)'\n"
    << "set title '" << title << "'\nplot '" << csv << "' using 1:" << names.size() + 2
    << " skip 1 with lines lc rgb 'gray' dt 2 title 'set-point'";
  const char* colors[] = {"#000000", "#c44e52", "#4c72b0", "#55a868"};
  for (std::size_t i = 0; i < names.size(); ++i) {
    g << ", '' using 1:" << i + 2 << " skip 1 with lines lw 1.5 lc rgb '" << colors[i % 4] << "' title '" << names[i] << "'";
  }
  g << "\n";
  return g.str();
}

nlohmann::json compare(const Context& ctx, const char* experiment, const char* scenario_name, const std::vector<Approach>& approaches,
                       bool noise_free, std::uint64_t seed, double duration_s, const std::string& out_dir, bool plots,
                       const std::string& title) {
  util::make_directory(out_dir);
  const Scenario sc = pick(scenario_name, duration_s);
  RunOptions ro;
  ro.noise_free = noise_free;
  ro.trace_step_s = kTraceStep;
  std::vector<RunResult> runs;
  std::vector<std::string> names;
  nlohmann::json j = {{"experiment", experiment}, {"scenario", sc.name}, {"description", describe(sc)},
                      {"seed", seed}, {"noise_free", noise_free}};
  for (Approach a : approaches) {
    runs.push_back(run(ctx, a, sc, seed, ro));
    names.emplace_back(name(a));
    j["cost"][name(a)] = runs.back().cost;
  }
  std::vector<const RunResult*> ptr;
  for (const auto& r : runs) ptr.push_back(&r);
  const std::string csv = std::string(experiment) + ".csv";
  write_x1(path_in(out_dir, csv), ptr, names);
  j["files"] = {csv};
  if (plots) {
    const std::string png = std::string(experiment) + ".png";
    util::run_gnuplot(out_dir, std::string(experiment) + ".gp", x1_plot(png, csv, title, names));
    j["files"].push_back(png);
  }
  return j;
}

}  // namespace

nlohmann::json run_e1(const Context& ctx, std::uint64_t seed, double duration_s, const std::string& out_dir, bool plots) {
  util::make_directory(out_dir);
  const Scenario sc = pick("a0.2-T4-d8-s16", duration_s);
  RunOptions ro;
  ro.trace_step_s = kTraceStep;
  const RunResult r = run(ctx, Approach::kAK, sc, seed, ro);
  // RMS of the measurement error at the samples and of AK's estimate at t_k.
  double ey[2] = {};
  for (std::size_t i = 0; i < r.samples.size(); ++i)
    for (int c = 0; c < 2; ++c) ey[c] += std::pow(r.samples[i].v[c] - r.sample_truth[i].v[c], 2);
  double ex[2] = {};
  std::size_t n_est = 0;
  std::vector<std::vector<double>> rows;
  for (const Point& e : r.estimates) {
    if (e.t_s > sc.duration_s - 1e-9) continue;
    const Point& x = truth_at(r, e.t_s);
    for (int c = 0; c < 2; ++c) ex[c] += std::pow(e.v[c] - x.v[c], 2);
    ++n_est;
    rows.push_back({e.t_s, e.v[0], e.v[1], x.v[0], x.v[1]});
  }
  util::write_csv(path_in(out_dir, "e1_estimates.csv"), {"t_s", "xhat1", "xhat2", "x1", "x2"}, rows);
  rows.clear();
  for (std::size_t i = 0; i < r.samples.size(); ++i) rows.push_back({r.samples[i].t_s, r.samples[i].v[0], r.samples[i].v[1]});
  util::write_csv(path_in(out_dir, "e1_samples.csv"), {"t_s", "y1", "y2"}, rows);
  rows.clear();
  for (const Point& p : r.truth) rows.push_back({p.t_s, p.v[0], p.v[1]});
  util::write_csv(path_in(out_dir, "e1_truth.csv"), {"t_s", "x1", "x2"}, rows);
  const double ns = static_cast<double>(r.samples.size());
  const double ne = static_cast<double>(n_est);
  nlohmann::json j = {{"experiment", "e1"},
                      {"scenario", sc.name},
                      {"description", describe(sc)},
                      {"seed", seed},
                      {"cost", r.cost},
                      {"rms_measurement_error_volts", {std::sqrt(ey[0] / ns), std::sqrt(ey[1] / ns)}},
                      {"rms_estimate_error_at_actuation_volts", {std::sqrt(ex[0] / ne), std::sqrt(ex[1] / ne)}},
                      {"files", {"e1_samples.csv", "e1_estimates.csv", "e1_truth.csv"}}};
  if (plots) {
    std::ostringstream g;
    g << util::gnuplot_png_terminal(1100, 800) << "set output 'e1.png'\n"
      << "set datafile separator ','\nset grid\nset key outside right\nset multiplot layout 2,1 title 'E1: noisy samples and AK estimates ("
      << describe(sc) << ", seed " << seed << ")'\n";
    for (int c = 1; c <= 2; ++c) {
      g << "set ylabel 'v" << c << " (V)'\n" << (c == 2 ? "set xlabel 't (s)'\n" : "")
        << "plot 'e1_samples.csv' using 1:" << c + 1 << " skip 1 with points pt 7 ps 0.4 lc rgb '#999999' title 'y" << c
        << "', 'e1_truth.csv' using 1:" << c + 1 << " skip 1 with lines lc rgb 'black' title 'x" << c
        << "', 'e1_estimates.csv' using 1:" << c + 1 << " skip 1 with points pt 2 ps 0.6 lc rgb '#c44e52' title 'AK x^" << c
        << " at t_k'\n";
    }
    g << "unset multiplot\n";
    util::run_gnuplot(out_dir, "e1.gp", g.str());
    j["files"].push_back("e1.png");
  }
  return j;
}

nlohmann::json run_e2(const Context& ctx, std::uint64_t seed, double duration_s, const std::string& out_dir, bool plots) {
  nlohmann::json j = compare(ctx, "e2", "a1-T2-d14-s16", {Approach::kI, Approach::kS, Approach::kA}, true, seed, duration_s,
                             out_dir, plots, "E2: delays only (d = 14 ms), no noise: I, S, A");
  return j;
}

nlohmann::json run_e3(const Context& ctx, std::uint64_t seed, double duration_s, const std::string& out_dir, bool plots) {
  return compare(ctx, "e3", "a1-T2-d14-s16", {Approach::kS, Approach::kA, Approach::kAK}, false, seed, duration_s, out_dir,
                 plots, "E3: delays (d = 14 ms), noise (s = 16) and process disturbance: S, A, AK");
}

}  // namespace oneshot::ncs
