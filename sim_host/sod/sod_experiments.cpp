/// @file sod_experiments.cpp
/// @brief E1 (ΔT), the design command and E2 (δt* over δy × ξ); see sod_experiments.hpp.
#include <algorithm>
#include <cmath>
#include <limits>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <fstream>
#include <iostream>
#include <sstream>
#include <stdexcept>

#include "oneshot/util/output_files.hpp"
#include "oneshot/util/statistics.hpp"
#include "sod_experiments.hpp"

namespace oneshot::sod {

void emit_json(const nlohmann::json& j, const std::string& path) {
  if (path.empty()) return;
  if (path == "-") {
    std::cout << j.dump(2) << "\n";
    return;
  }
  util::write_json(path, j);
}

namespace {
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
std::string fmt(const char* f, double v) {
  char b[64];
  std::snprintf(b, sizeof b, f, v);
  return b;
}
nlohmann::json num_or_null(bool ok, double v) { return ok ? nlohmann::json(v) : nlohmann::json(nullptr); }
}  // namespace

MeanGap measure_mean_gap(const SodModel& model, const StudyOptions& opt, double delta_y) {
  engine::SweepSpec spec;
  spec.study = "sod";
  spec.experiment = "mean-gap";
  spec.approaches = {"sod"};
  spec.scenarios = {"dy=" + fmt("%g", delta_y)};
  spec.first_seed = opt.seed;
  spec.seeds = opt.seeds;
  spec.metrics = {"gap1", "gap2", "sends1", "sends2"};
  RunConfig cfg;
  cfg.sender = SenderKind::kSod;
  cfg.delta_y[0] = cfg.delta_y[1] = delta_y;
  cfg.loss = 0;
  cfg.amplitude = opt.amplitude;
  cfg.steps = opt.steps;
  const double duration = static_cast<double>(opt.steps) * model.period_s();
  const engine::SweepResults r = engine::run_sweep(spec, engine::Shard{}, opt.threads,
      [&](std::size_t, std::size_t, std::uint64_t seed) {
        const RunResult x = simulate_run(model, cfg, seed);
        return std::vector<double>{duration / x.sends[0], duration / x.sends[1], x.sends[0], x.sends[1]};
      }, "sod E1");
  MeanGap g;
  for (std::size_t i = 0; i < kNodes; ++i) {
    std::vector<double> gap, sends;
    for (std::size_t k = 0; k < opt.seeds; ++k) {
      gap.push_back(r.at(0, 0, k, i));
      sends.push_back(r.at(0, 0, k, 2 + i));
    }
    const util::Summary s = util::summarize(gap);
    g.mean_s[i] = s.mean;
    g.ci95_s[i] = s.ci95;
    g.sends[i] = util::summarize(sends).mean;
  }
  return g;
}

nlohmann::json run_mean_gap(const SodModel& model, const StudyOptions& opt, const std::vector<double>& delta_ys) {
  nlohmann::json j = {{"experiment", "E1"}, {"plant", model.plant_name}, {"seeds", opt.seeds}, {"first_seed", opt.seed},
                      {"amplitude", opt.amplitude}, {"steps", opt.steps}, {"period_s", model.period_s()},
                      {"definition", "Delta_T_i = N T / packets_i of lossless plain SOD, mean over seeds"}};
  for (double dy : delta_ys) {
    const MeanGap g = measure_mean_gap(model, opt, dy);
    j["rows"].push_back({{"delta_y", dy},
                         {"mean_gap_s", {g.mean_s[0], g.mean_s[1]}},
                         {"mean_gap_ci95_s", {g.ci95_s[0], g.ci95_s[1]}},
                         {"packets", {g.sends[0], g.sends[1]}}});
  }
  return j;
}

namespace {

nlohmann::json design_json(const DeltaTDesign& d, double loss) {
  nlohmann::json e = {{"loss", loss}};
  for (std::size_t i = 0; i < kNodes; ++i) {
    const NodeDeltaT& n = d.node[i];
    e["delta_t_s"].push_back(num_or_null(n.bounded, n.delta_t_s));
    e["n_t"].push_back(num_or_null(n.bounded, n.n_t));
    e["dbar"].push_back(num_or_null(std::isfinite(n.dbar), n.dbar));
    e["delta_t_times_loss_s"].push_back(num_or_null(n.bounded, n.delta_t_times_loss));
    e["unbounded_reason"].push_back(n.bounded ? nlohmann::json(nullptr) : nlohmann::json(n.reason));
  }
  e["active_constraints"] = d.active;
  e["p_diag_at_optimum"] = {d.p_diag[0], d.p_diag[1]};
  e["packets_per_s_time_rule"] = d.packets_per_s;
  e["grid_check"] = {{"best_packets_per_s", d.grid_best_packets_per_s}, {"passed", d.grid_check_passed}};
  e["riccati_solves"] = d.riccati_solves;
  return e;
}

}  // namespace

DeltaTDesign design_at(const SodModel& model, const StudyOptions& opt, const MeanGap& g, double delta_y, double loss) {
  DesignInputs in;
  in.delta_y[0] = in.delta_y[1] = delta_y;
  in.loss[0] = in.loss[1] = loss;
  in.mean_gap_s[0] = g.mean_s[0];
  in.mean_gap_s[1] = g.mean_s[1];
  in.mu = opt.mu;
  return design_delta_t(model, in);
}

nlohmann::json run_design(const SodModel& model, const StudyOptions& opt) {
  const MeanGap g = measure_mean_gap(model, opt, opt.delta_y);
  nlohmann::json j = {{"experiment", "design"}, {"plant", model.plant_name}, {"delta_y", opt.delta_y}, {"mu", opt.mu},
                      {"seeds", opt.seeds}, {"first_seed", opt.seed}, {"amplitude", opt.amplitude},
                      {"mean_gap_s", {g.mean_s[0], g.mean_s[1]}}, {"mean_gap_ci95_s", {g.ci95_s[0], g.ci95_s[1]}}};
  double lo[kNodes] = {std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity()};
  double hi[kNodes] = {0, 0};
  bool any_bounded[kNodes] = {false, false};
  for (double xi : opt.design_losses) {
    const DeltaTDesign d = design_at(model, opt, g, opt.delta_y, xi);
    j["p0_diag"] = {d.p0_diag[0], d.p0_diag[1]};
    j["per_loss"].push_back(design_json(d, xi));
    for (std::size_t i = 0; i < kNodes; ++i) {
      if (!d.node[i].bounded) continue;
      any_bounded[i] = true;
      lo[i] = std::min(lo[i], d.node[i].delta_t_times_loss);
      hi[i] = std::max(hi[i], d.node[i].delta_t_times_loss);
    }
  }
  for (std::size_t i = 0; i < kNodes; ++i)
    j["delta_t_times_loss_relative_spread"].push_back(num_or_null(any_bounded[i], any_bounded[i] ? (hi[i] - lo[i]) / lo[i] : 0.0));
  return j;
}

nlohmann::json run_grid(const SodModel& model, const StudyOptions& opt, const std::vector<double>& delta_ys,
                        const std::vector<double>& losses) {
  nlohmann::json j = {{"experiment", "E2"}, {"plant", model.plant_name}, {"mu", opt.mu}, {"seeds", opt.seeds},
                      {"first_seed", opt.seed}};
  std::vector<std::vector<double>> rows;
  for (double dy : delta_ys) {
    const MeanGap g = measure_mean_gap(model, opt, dy);
    nlohmann::json row = {{"delta_y", dy}, {"mean_gap_s", {g.mean_s[0], g.mean_s[1]}}};
    for (double xi : losses) {
      const DeltaTDesign d = design_at(model, opt, g, dy, xi);
      row["per_loss"].push_back(design_json(d, xi));
      rows.push_back({dy, xi, d.node[0].bounded ? d.node[0].delta_t_s : kNaN, d.node[1].bounded ? d.node[1].delta_t_s : kNaN,
                      g.mean_s[0], g.mean_s[1]});
    }
    j["rows"].push_back(row);
  }
  // Grouped by loss rate, so that gnuplot draws one connected line per ξ.
  std::stable_sort(rows.begin(), rows.end(), [](const std::vector<double>& a, const std::vector<double>& b) { return a[1] < b[1]; });
  util::make_directory(opt.out_dir);
  const std::string csv = (std::filesystem::path(opt.out_dir) / "e2_delta_t.csv").string();
  // An unbounded δt* (brief §5: the constraint never binds) is written as gnuplot's missing value.
  util::write_csv(csv, {"delta_y", "loss", "delta_t1_s", "delta_t2_s", "mean_gap1_s", "mean_gap2_s"}, rows,
                 util::NonFinite::kMissing);
  j["files"] = {"e2_delta_t.csv"};
  if (opt.plots) {
    std::ostringstream g;
    g << util::gnuplot_png_terminal(1100, 500) << "set output 'e2_delta_t.png'\n"
      << "set datafile separator ','\nset datafile missing 'nan'\nset grid\nset multiplot layout 1,2\n"
      << "set xlabel 'delta_y'\nset logscale y\nset key top left\nset xrange [0:*]\n";
    for (int node = 1; node <= 2; ++node) {
      g << "set title 'E2: delta_t*_" << node << " (s), mu = " << opt.mu << " (missing: unbounded)'\nset ylabel 'delta_t* (s)'\nplot ";
      for (std::size_t s = 0; s < losses.size(); ++s) {
        g << (s ? ", " : "") << "'e2_delta_t.csv' using 1:($2 == " << losses[s] << " ? $" << 2 + node
          << " : 1/0) skip 1 with linespoints title 'xi = " << losses[s] << "'";
      }
      g << "\n";
    }
    g << "unset multiplot\n";
    util::run_gnuplot(opt.out_dir, "e2_delta_t.gp", g.str());
    j["files"].push_back("e2_delta_t.png");
  }
  return j;
}

}  // namespace oneshot::sod
