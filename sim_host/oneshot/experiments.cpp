/// @file experiments.cpp
/// @brief Experiments 1–3 of the brief, single runs and the benchmark (experiment 4: table1.cpp,
///        5: exectime_experiment.cpp).
#include "oneshot_experiments.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <iostream>
#include <map>
#include <sstream>

#include "oneshot/sim/engine_benchmark.hpp"
#include "oneshot/util/output_files.hpp"
#include "oneshot/util/parallel.hpp"
#include "oneshot/util/progress_bar.hpp"
#include "oneshot/util/statistics.hpp"

namespace oneshot::sim {

std::string path_in(const CommonOptions& opt, const std::string& name) {
  return (std::filesystem::path(opt.out_dir) / name).string();
}

nlohmann::json common_json(const SimContext& ctx, const CommonOptions& opt) {
  nlohmann::json j;
  j["plant"] = ctx.plant().name;
  j["number_format"] = to_string(opt.format);
  j["discretizer"] = to_string(opt.discretizer);
  j["noise_model"] = opt.noise == NoiseModel::kExact ? "exact" : "constant";
  j["seed"] = opt.seed;
  return j;
}

namespace {

using Clock = std::chrono::steady_clock;

std::string state_label(const SimContext& ctx, std::size_t i) { return ctx.plant().states.at(i); }

/// Value of the dense trace at time t (trace step divides the period: exact grid point).
const TracePoint& trace_at(const RunResult& r, double t_s, std::int32_t step_us) {
  const auto index = static_cast<std::size_t>(std::llround(t_s * 1e6 / step_us));
  return r.trace.at(std::min(index, r.trace.size() - 1));
}

/// One curve of a gnuplot `plot`: columns of `file` ('' repeats the previous file), style, title.
struct PlotSeries {
  const char* file;
  const char* using_columns;
  const char* with;
  const char* title;
};

/// `plot <series>, <series>...` on one line (every file has a header row to skip).
std::string plot_command(const std::vector<PlotSeries>& series) {
  std::string p;
  for (const PlotSeries& c : series) {
    p += (p.empty() ? "plot '" : ", '") + std::string(c.file) + "' using " + c.using_columns + " skip 1 with " + c.with +
         " title '" + c.title + "'";
  }
  return p + "\n";
}

}  // namespace

RunOptions run_options(const CommonOptions& opt, Approach a) {
  RunOptions r;
  r.approach = a;
  r.format = opt.format;
  r.discretizer = opt.discretizer;
  r.noise = opt.noise;
  r.board = opt.board;
  return r;
}

nlohmann::json run_noise_experiment(const SimContext& ctx, const CommonOptions& opt, double duration_s) {
  const Scenario sc = uniform_scenario("noise-demo", 20'000, 0.2, 1.0, duration_s);
  RunOptions ro = run_options(opt, Approach::kB);
  ro.record_jobs = true;
  ro.trace_step_us = 1000;
  const RunResult r = simulate(ctx, sc, opt.seed, ro);
  const std::size_t n = ctx.plant().n();
  std::vector<std::vector<double>> rows;
  double se_meas = 0;
  double se_est = 0;
  for (const JobRecord& j : r.job_records) {
    const TracePoint& truth = trace_at(r, j.t_apply_s, ro.trace_step_us);
    std::vector<double> row = {j.t_sample_s, j.y_volts, j.t_apply_s};
    for (std::size_t i = 0; i < n; ++i) row.push_back(j.estimate[i]);
    for (std::size_t i = 0; i < n; ++i) row.push_back(truth.x[i]);
    row.push_back(j.setpoint_volts);
    rows.push_back(row);
    se_meas += (j.y_volts - j.x_true[0]) * (j.y_volts - j.x_true[0]);
    se_est += (j.estimate[0] - truth.x[0]) * (j.estimate[0] - truth.x[0]);
  }
  std::vector<std::string> header = {"t_sample_s", "y_volts", "t_apply_s"};
  for (std::size_t i = 0; i < n; ++i) header.push_back(state_label(ctx, i) + "_estimate");
  for (std::size_t i = 0; i < n; ++i) header.push_back(state_label(ctx, i) + "_true");
  header.push_back("setpoint_volts");
  util::write_csv(path_in(opt, "noise_jobs.csv"), header, rows);
  std::vector<std::vector<double>> trace;
  for (const TracePoint& p : r.trace) {
    std::vector<double> row = {p.t_s};
    row.insert(row.end(), p.x.begin(), p.x.end());
    row.push_back(p.setpoint_volts);
    trace.push_back(row);
  }
  std::vector<std::string> theader = {"t_s"};
  for (std::size_t i = 0; i < n; ++i) theader.push_back(state_label(ctx, i));
  theader.push_back("setpoint_volts");
  util::write_csv(path_in(opt, "noise_trace.csv"), theader, trace);

  const double rms_meas = std::sqrt(se_meas / static_cast<double>(r.job_records.size()));
  const double rms_est = std::sqrt(se_est / static_cast<double>(r.job_records.size()));
  if (opt.plots) {
    std::ostringstream g;
    g << util::gnuplot_png_terminal(1100, 700) << "set output 'noise.png'\nset datafile separator ','\nset key outside right top\n"
      << "set multiplot layout " << std::min<std::size_t>(n, 2) << ",1 title 'Noise removal: one-shot controller with half Kalman filter (jitter 0-20 ms)'\n"
      << "set grid\nset ylabel " << util::gnuplot_quote(state_label(ctx, 0) + " (V)") << "\n"
      << "plot 'noise_jobs.csv' using 1:2 skip 1 with points pt 7 ps 0.5 lc rgb '#999999' title 'measured (ADC)', "
      << "'noise_trace.csv' using 1:" << n + 2 << " skip 1 with lines dt 2 lw 1.5 lc rgb 'black' title 'set-point', "
      << "'noise_trace.csv' using 1:2 skip 1 with lines lw 2 lc rgb '#1f77b4' title 'true', "
      << "'noise_jobs.csv' using 3:4 skip 1 with steps lw 2 lc rgb '#d62728' title 'estimate'\n";
    if (n >= 2) {
      g << "set xlabel 'time (s)'\nset ylabel " << util::gnuplot_quote(state_label(ctx, 1) + " (V)") << "\n"
        << "plot 'noise_trace.csv' using 1:3 skip 1 with lines lw 2 lc rgb '#1f77b4' title 'true', "
        << "'noise_jobs.csv' using 3:5 skip 1 with steps lw 2 lc rgb '#d62728' title 'estimate'\n";
    }
    g << "unset multiplot\n";
    util::run_gnuplot(opt.out_dir, "noise.gp", g.str());
  }
  nlohmann::json j = common_json(ctx, opt);
  j["experiment"] = "noise";
  j["approach"] = "B";
  j["duration_s"] = r.duration_s;
  j["rms_measurement_error_volts"] = rms_meas;
  j["rms_estimate_error_volts"] = rms_est;
  j["noise_reduction_factor"] = rms_meas / rms_est;
  j["files"] = {"noise_jobs.csv", "noise_trace.csv", "noise.png"};
  return j;
}

nlohmann::json run_jitter_experiment(const SimContext& ctx, const CommonOptions& opt, double duration_s,
                                     std::int32_t jitter_us) {
  const Scenario sc = uniform_scenario("jitter-demo", jitter_us, 0.2, 1.0, duration_s);
  const std::array<Approach, 4> approaches = {Approach::kA, Approach::kB, Approach::kD, Approach::kE};
  std::vector<RunResult> results(approaches.size());
  util::parallel_for(approaches.size(), util::worker_count(opt.threads), nullptr, [&](std::size_t i) {
    RunOptions ro = run_options(opt, approaches[i]);
    ro.trace_step_us = 1000;
    results[i] = simulate(ctx, sc, opt.seed, ro);
  });
  std::vector<std::vector<double>> rows;
  for (std::size_t k = 0; k < results[0].trace.size(); ++k) {
    std::vector<double> row = {results[0].trace[k].t_s, results[0].trace[k].setpoint_volts};
    for (const RunResult& r : results) row.push_back(r.trace[k].x[0]);
    rows.push_back(row);
  }
  const std::string v = state_label(ctx, 0);
  util::write_csv(path_in(opt, "jitter.csv"), {"t_s", "setpoint_volts", v + "_A", v + "_B", v + "_D", v + "_E"}, rows);
  if (opt.plots) {
    std::ostringstream g;
    g << util::gnuplot_png_terminal(1100, 700) << "set output 'jitter.png'\nset datafile separator ','\nset key top left box opaque\nset grid\n"
      << "set title 'Response under jitter (release 0-" << jitter_us / 1000.0 << " ms): one-shot + half Kalman vs standard controllers'\n"
      << "set xlabel 'time (s)'\nset ylabel " << util::gnuplot_quote(v + " (V)") << "\n"
      << plot_command({{"jitter.csv", "1:2", "lines dt 2 lw 1.5 lc rgb 'black'", "set-point"},
                       {"", "1:3", "lines lw 3 lc rgb '#bbbbbb'", "A: standard + Kalman, no jitter"},
                       {"", "1:4", "lines lw 1.5 lc rgb '#d62728'", "B: one-shot + half Kalman"},
                       {"", "1:5", "lines lw 1.5 lc rgb '#1f77b4'", "D: standard + Kalman"},
                       {"", "1:6", "lines lw 1.5 lc rgb '#2ca02c'", "E: standard, no Kalman"}});
    util::run_gnuplot(opt.out_dir, "jitter.gp", g.str());
  }
  nlohmann::json j = common_json(ctx, opt);
  j["experiment"] = "jitter";
  j["jitter_release_max_us"] = jitter_us;
  for (std::size_t i = 0; i < approaches.size(); ++i) j["cost"][std::string(1, info(approaches[i]).letter)] = results[i].cost.total();
  j["files"] = {"jitter.csv", "jitter.png"};
  return j;
}

nlohmann::json run_gain_experiment(const SimContext& ctx, const CommonOptions& opt, double duration_s, double p0_scale) {
  const Scenario sc = uniform_scenario("gain-demo", 20'000, 0.2, 1.0, duration_s);
  const std::array<Approach, 3> approaches = {Approach::kB, Approach::kC, Approach::kA};
  std::vector<RunResult> results(approaches.size());
  for (std::size_t i = 0; i < approaches.size(); ++i) {
    RunOptions ro = run_options(opt, approaches[i]);
    ro.record_jobs = true;
    ro.p0_scale = p0_scale;
    results[i] = simulate(ctx, sc, opt.seed, ro);
  }
  std::vector<std::vector<double>> rows;
  double spread[3] = {0, 0, 0};
  for (std::size_t k = 0; k < results[0].job_records.size(); ++k) {
    std::vector<double> row = {static_cast<double>(k)};
    for (std::size_t i = 0; i < 3; ++i) {
      row.push_back(results[i].job_records[k].t_sample_s);
      row.push_back(results[i].job_records[k].gain0);
    }
    rows.push_back(row);
  }
  // Spread of K₁ over the second half (after convergence): jitter moves the half/complete gains.
  for (std::size_t i = 0; i < 3; ++i) {
    double lo = 1e300;
    double hi = -1e300;
    const auto& jr = results[i].job_records;
    for (std::size_t k = jr.size() / 2; k < jr.size(); ++k) {
      lo = std::min(lo, jr[k].gain0);
      hi = std::max(hi, jr[k].gain0);
    }
    spread[i] = hi - lo;
  }
  util::write_csv(path_in(opt, "gain.csv"), {"job", "t_half_s", "K1_half", "t_complete_s", "K1_complete", "t_standard_s", "K1_standard"},
            rows);
  if (opt.plots) {
    std::ostringstream g;
    g << util::gnuplot_png_terminal(1100, 700) << "set output 'gain.png'\nset datafile separator ','\nset key top right box opaque\nset grid\n"
      << "set title 'First Kalman gain element over time (P0 = " << p0_scale << " x steady state)'\n"
      << "set xlabel 'time (s)'\nset ylabel 'K(1)'\n"
      << plot_command({{"gain.csv", "2:3", "linespoints pt 7 ps 0.6 lw 1.5 lc rgb '#d62728'", "half Kalman (one-shot, jitter)"},
                       {"", "4:5", "linespoints pt 6 ps 0.9 lw 1 dt 2 lc rgb '#9467bd'", "complete Kalman (one-shot, jitter)"},
                       {"", "6:7", "linespoints pt 5 ps 0.5 lw 1.5 lc rgb '#1f77b4'", "standard controller + Kalman, no jitter"}});
    util::run_gnuplot(opt.out_dir, "gain.gp", g.str());
  }
  nlohmann::json j = common_json(ctx, opt);
  j["experiment"] = "gain";
  j["p0_scale"] = p0_scale;
  j["steady_state_K1"] = ctx.design().kalman_gain(0, 0);
  j["final_K1"] = {{"half", results[0].job_records.back().gain0},
                   {"complete", results[1].job_records.back().gain0},
                   {"standard", results[2].job_records.back().gain0}};
  j["K1_spread_second_half"] = {{"half", spread[0]}, {"complete", spread[1]}, {"standard", spread[2]}};
  j["files"] = {"gain.csv", "gain.png"};
  return j;
}

nlohmann::json run_single(const SimContext& ctx, const CommonOptions& opt, const Scenario& scenario, Approach approach,
                          std::int32_t trace_step_us) {
  RunOptions ro = run_options(opt, approach);
  ro.record_jobs = true;
  ro.trace_step_us = trace_step_us;
  const RunResult r = simulate(ctx, scenario, opt.seed, ro);
  const std::size_t n = ctx.plant().n();
  std::vector<std::vector<double>> rows;
  for (const JobRecord& jr : r.job_records) {
    std::vector<double> row = {jr.t_sample_s, jr.t_apply_s, static_cast<double>(jr.tau_us), jr.y_volts};
    row.insert(row.end(), jr.x_true.begin(), jr.x_true.end());
    row.insert(row.end(), jr.estimate.begin(), jr.estimate.end());
    row.push_back(jr.gain0);
    row.push_back(jr.setpoint_volts);
    row.push_back(jr.u_volts);
    rows.push_back(row);
  }
  std::vector<std::string> header = {"t_sample_s", "t_apply_s", "tau_us", "y_volts"};
  for (std::size_t i = 0; i < n; ++i) header.push_back(state_label(ctx, i) + "_true_at_sample");
  for (std::size_t i = 0; i < n; ++i) header.push_back(state_label(ctx, i) + "_estimate");
  header.insert(header.end(), {"K1", "setpoint_volts", "u_volts"});
  util::write_csv(path_in(opt, "run_jobs.csv"), header, rows);
  if (trace_step_us > 0) {
    std::vector<std::vector<double>> trace;
    for (const TracePoint& p : r.trace) {
      std::vector<double> row = {p.t_s};
      row.insert(row.end(), p.x.begin(), p.x.end());
      row.push_back(p.setpoint_volts);
      row.push_back(p.u_volts);
      trace.push_back(row);
    }
    std::vector<std::string> th = {"t_s"};
    for (std::size_t i = 0; i < n; ++i) th.push_back(state_label(ctx, i));
    th.insert(th.end(), {"setpoint_volts", "u_volts"});
    util::write_csv(path_in(opt, "run_trace.csv"), th, trace);
    if (opt.plots) {
      std::ostringstream g;
      g << util::gnuplot_png_terminal(1100, 700) << "set output 'run.png'\nset datafile separator ','\nset key outside right top\nset grid\n"
        << "set multiplot layout 2,1 title "
        << util::gnuplot_quote("Run: approach " + std::string(1, info(approach).letter) + " (" + info(approach).description +
                         "), scenario " + scenario.name + ", seed " + std::to_string(opt.seed))
        << "\nset ylabel " << util::gnuplot_quote(state_label(ctx, 0) + " (V)") << "\nplot 'run_trace.csv' using 1:" << n + 2
        << " skip 1 with lines dt 2 lc rgb 'black' title 'set-point', '' using 1:2 skip 1 with lines lw 2 lc rgb '#1f77b4' title 'true', "
        << "'run_jobs.csv' using 2:" << 5 + n << " skip 1 with steps lc rgb '#d62728' title 'estimate'\n"
        << "set xlabel 'time (s)'\nset ylabel 'u (V)'\nplot 'run_trace.csv' using 1:" << n + 3
        << " skip 1 with steps lw 1.5 lc rgb '#2ca02c' title 'commanded input'\nunset multiplot\n";
      util::run_gnuplot(opt.out_dir, "run.gp", g.str());
    }
  }
  nlohmann::json j = common_json(ctx, opt);
  j["experiment"] = "run";
  j["approach"] = std::string(1, info(approach).letter);
  j["scenario"] = scenario.name;
  j["jitter"] = scenario.jitter.describe();
  j["duration_s"] = r.duration_s;
  j["cost"] = {{"total", r.cost.total()}, {"state", r.cost.state}, {"input", r.cost.input}, {"noise", r.cost.noise}};
  j["jobs"] = r.jobs;
  j["overruns"] = r.overruns;
  j["faults"] = r.faults;
  return j;
}

nlohmann::json run_benchmark(const SimContext& ctx, const CommonOptions& opt, double simulated_s) {
  const Scenario sc = uniform_scenario("benchmark", 20'000, 0.2, 1.0, simulated_s);
  nlohmann::json j = common_json(ctx, opt);
  j["experiment"] = "benchmark";
  j["simulated_seconds_per_run"] = simulated_s;
  for (Approach a : {Approach::kA, Approach::kB, Approach::kE}) {
    double best = 0;
    double events_per_s = 0;
    for (int rep = 0; rep < 3; ++rep) {
      const auto t0 = Clock::now();
      const RunResult r = simulate(ctx, sc, opt.seed + static_cast<std::uint64_t>(rep), run_options(opt, a));
      const double wall = std::chrono::duration<double>(Clock::now() - t0).count();
      best = std::max(best, r.duration_s / wall);
      events_per_s = std::max(events_per_s, static_cast<double>(r.events) / wall);
    }
    j["real_time_factor_one_core"][std::string(1, info(a).letter)] = best;
    j["events_per_second_one_core"][std::string(1, info(a).letter)] = events_per_s;
  }
  // The engine on a networked loop (firmware nodes, a lossy link, a CAN bus with background traffic).
  nlohmann::json best_net;
  for (int rep = 0; rep < 3; ++rep) {
    const nlohmann::json n = networked_loop_benchmark(simulated_s, opt.seed + static_cast<std::uint64_t>(rep));
    if (best_net.is_null() || n["events_per_second"].get<double>() > best_net["events_per_second"].get<double>()) best_net = n;
  }
  j["networked_loop"] = best_net;
  return j;
}

}  // namespace oneshot::sim
