/// @file sod_curve.cpp
/// @brief E3 d (error against packets, δt swept, beside a periodic sender with the same
///        packet budget) and E4 (error over time); see sod_experiments.hpp.
#include <cmath>
#include <limits>
#include <sstream>

#include "oneshot/engine/sweep.hpp"
#include "oneshot/node/send_cause.hpp"
#include "oneshot/util/number_text.hpp"
#include "oneshot/util/output_files.hpp"
#include "oneshot/util/statistics.hpp"
#include "sod_experiments.hpp"

namespace oneshot::sod {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

using util::path_in;
std::string g6(double v) { return util::format_g(v, 6); }
using util::mean_ci_json;

}  // namespace

nlohmann::json run_curve(const SodModel& model, const StudyOptions& opt, const std::vector<double>& delta_ts,
                         const std::vector<double>& losses) {
  if (opt.seeds < 2) throw std::invalid_argument("sod curve needs at least 2 seeds for confidence intervals");
  const double T = model.period_s();
  // Sweep 1: modified SOD at each δt (both nodes alike), plus plain SOD (δt = ∞).
  engine::SweepSpec spec;
  spec.study = "sod";
  spec.experiment = "curve";
  for (double dt : delta_ts) spec.approaches.push_back("msod dt=" + g6(dt));
  spec.approaches.push_back("sod");
  for (double xi : losses) spec.scenarios.push_back("xi=" + g6(xi));
  spec.first_seed = opt.seed;
  spec.seeds = opt.seeds;
  spec.metrics = {"e1", "e2", "packets", "nees"};
  auto base = [&](double xi) {
    RunConfig c;
    c.delta_y[0] = c.delta_y[1] = opt.delta_y;
    c.loss = xi;
    c.amplitude = opt.amplitude;
    c.steps = opt.steps;
    return c;
  };
  auto metrics = [](const RunResult& x) {
    return std::vector<double>{x.e[0], x.e[1], x.sends[0] + x.sends[1], x.nees};
  };
  const engine::SweepResults r1 = engine::run_sweep(spec, engine::Shard{}, opt.threads,
      [&](std::size_t a, std::size_t s, std::uint64_t seed) {
        RunConfig c = base(losses[s]);
        if (a < delta_ts.size()) {
          c.sender = SenderKind::kModifiedSod;
          c.n_t[0] = c.n_t[1] = static_cast<std::uint32_t>(std::max(1.0, std::round(delta_ts[a] / T)));
        }
        return metrics(simulate_run(model, c, seed));
      }, "sod curve (SOD)");
  // Sweep 2: periodic senders whose period gives each point's mean packet count.
  const std::size_t na = spec.approaches.size(), ns = losses.size(), seeds = opt.seeds;
  auto stat = [&](const engine::SweepResults& r, std::size_t a, std::size_t s, std::size_t m) {
    std::vector<double> v;
    for (std::size_t k = 0; k < seeds; ++k) v.push_back(r.at(a, s, k, m));
    return util::summarize(v);
  };
  std::vector<std::vector<std::uint32_t>> every(na, std::vector<std::uint32_t>(ns));
  for (std::size_t a = 0; a < na; ++a)
    for (std::size_t s = 0; s < ns; ++s) {
      const double per_node = stat(r1, a, s, 2).mean / 2;
      every[a][s] = static_cast<std::uint32_t>(std::max(1.0, std::round(static_cast<double>(opt.steps + 1) / per_node)));
    }
  engine::SweepSpec spec2 = spec;
  spec2.experiment = "curve-periodic";
  for (auto& n : spec2.approaches) n = "periodic budget of " + n;
  const engine::SweepResults r2 = engine::run_sweep(spec2, engine::Shard{}, opt.threads,
      [&](std::size_t a, std::size_t s, std::uint64_t seed) {
        RunConfig c = base(losses[s]);
        c.sender = SenderKind::kPeriodic;
        c.filter = FilterKind::kPredictOnly;
        c.every[0] = c.every[1] = every[a][s];
        return metrics(simulate_run(model, c, seed));
      }, "sod curve (periodic)");
  nlohmann::json j = {{"experiment", "E3d curve"}, {"plant", model.plant_name}, {"delta_y", opt.delta_y},
                      {"seeds", seeds}, {"first_seed", opt.seed}, {"amplitude", opt.amplitude}, {"steps", opt.steps}};
  std::vector<std::vector<double>> csv;
  for (std::size_t s = 0; s < ns; ++s) {
    for (std::size_t a = 0; a < na; ++a) {
      const bool is_sod = a == delta_ts.size();
      nlohmann::json row = {{"loss", losses[s]}, {"delta_t_s", is_sod ? nlohmann::json(nullptr) : nlohmann::json(delta_ts[a])},
                            {"sender", is_sod ? "sod" : "msod"}, {"periodic_every", every[a][s]}};
      std::vector<double> line = {losses[s], is_sod ? -1.0 : delta_ts[a], static_cast<double>(every[a][s])};
      for (const engine::SweepResults* r : {&r1, &r2}) {
        nlohmann::json part;
        for (std::size_t m = 0; m < 4; ++m) {
          const util::Summary x = stat(*r, a, s, m);
          part[spec.metrics[m]] = mean_ci_json(x);
          line.push_back(x.mean);
          line.push_back(x.ci95);
        }
        row[r == &r1 ? "event" : "periodic"] = part;
      }
      for (std::size_t m = 0; m < 2; ++m) {  // paired: event − periodic at the same seed
        std::vector<double> d;
        for (std::size_t k = 0; k < seeds; ++k) d.push_back(r1.at(a, s, k, m) - r2.at(a, s, k, m));
        row["paired_event_minus_periodic"][spec.metrics[m]] = mean_ci_json(util::summarize(d));
      }
      j["rows"].push_back(row);
      csv.push_back(line);
    }
  }
  util::make_directory(opt.out_dir);
  util::write_csv(path_in(opt.out_dir, "curve.csv"),
                 {"loss", "delta_t_s", "periodic_every", "ev_e1", "ev_e1_ci", "ev_e2", "ev_e2_ci", "ev_packets",
                  "ev_packets_ci", "ev_nees", "ev_nees_ci", "pe_e1", "pe_e1_ci", "pe_e2", "pe_e2_ci", "pe_packets",
                  "pe_packets_ci", "pe_nees", "pe_nees_ci"},
                 csv);
  j["files"] = {"curve.csv"};
  if (opt.plots) {
    std::ostringstream g;
    g << util::gnuplot_png_terminal(1100, static_cast<int>(450 * ns)) << "set output 'curve.png'\n"
      << "set datafile separator ','\nset grid\nset logscale xy\nset multiplot layout " << ns << ",2\n"
      << "set xlabel 'packets per run (both nodes)'\nset key top right\n";
    for (std::size_t s = 0; s < ns; ++s)
      for (int node = 1; node <= 2; ++node) {
        const int ec = 2 + 2 * node, pc = 10 + 2 * node;
        g << "set title 'E3d: e_" << node << " vs packets, xi = " << losses[s] << " (95 % CI)'\nset ylabel 'e_" << node
          << "'\nplot 'curve.csv' using ($1 == " << losses[s] << " && $2 > 0 ? $8 : 1/0):" << ec << ":" << ec + 1
          << " skip 1 with yerrorlines title 'modified SOD, dt swept', '' using ($1 == " << losses[s]
          << " ? $16 : 1/0):" << pc << ":" << pc + 1 << " skip 1 with yerrorlines title 'periodic, same budget', "
          << "'' using ($1 == " << losses[s] << " && $2 < 0 ? $8 : 1/0):" << ec << " skip 1 with points pt 7 ps 1.5 title 'plain SOD'\n";
      }
    g << "unset multiplot\n";
    util::run_gnuplot(opt.out_dir, "curve.gp", g.str());
    j["files"].push_back("curve.png");
  }
  return j;
}

nlohmann::json run_traces(const SodModel& model, const StudyOptions& opt, double loss) {
  const MeanGap g = measure_mean_gap(model, opt, opt.delta_y);
  const DeltaTDesign d = design_at(model, opt, g, opt.delta_y, loss);
  const double T = model.period_s();
  const std::size_t per_bin = static_cast<std::size_t>(std::max(1.0, std::round(0.5 / T)));  // 0.5 s bins
  const std::size_t bins = static_cast<std::size_t>(opt.steps) / per_bin;
  auto config = [&](std::size_t a) {
    RunConfig c;
    c.sender = a == 0 ? SenderKind::kSod : SenderKind::kModifiedSod;
    c.delta_y[0] = c.delta_y[1] = opt.delta_y;
    c.n_t[0] = d.node[0].bounded ? d.node[0].n_t : 0;
    c.n_t[1] = d.node[1].bounded ? d.node[1].n_t : 0;
    c.loss = loss;
    c.amplitude = opt.amplitude;
    c.steps = opt.steps;
    return c;
  };
  engine::SweepSpec spec;
  spec.study = "sod";
  spec.experiment = "traces";
  spec.approaches = {"sod-held", "msod"};
  spec.scenarios = {"xi=" + g6(loss)};
  spec.first_seed = opt.seed;
  spec.seeds = opt.seeds;
  for (int i = 1; i <= 2; ++i)
    for (std::size_t b = 0; b < bins; ++b) spec.metrics.push_back("e" + std::to_string(i) + "_bin" + std::to_string(b));
  const engine::SweepResults r = engine::run_sweep(spec, engine::Shard{}, opt.threads,
      [&](std::size_t a, std::size_t, std::uint64_t seed) {
        RunTrace tr;
        simulate_run(model, config(a), seed, &tr);
        std::vector<double> v(2 * bins, 0.0);
        for (std::size_t i = 0; i < kNodes; ++i)
          for (std::size_t b = 0; b < bins; ++b) {
            double acc = 0;
            for (std::size_t k = 1 + b * per_bin; k <= (b + 1) * per_bin; ++k) {
              const double e = tr.x[i][k] - tr.x_hat[i][k];
              acc += e * e;
            }
            v[i * bins + b] = acc / static_cast<double>(per_bin);
          }
        return v;
      }, "sod E4");
  std::vector<std::vector<double>> rows;
  for (std::size_t b = 0; b < bins; ++b) {
    std::vector<double> line = {(static_cast<double>(b) + 0.5) * static_cast<double>(per_bin) * T};
    for (std::size_t a = 0; a < 2; ++a)
      for (std::size_t i = 0; i < kNodes; ++i) {
        std::vector<double> x;
        for (std::size_t k = 0; k < opt.seeds; ++k) x.push_back(r.at(a, 0, k, i * bins + b));
        const util::Summary sm = util::summarize(x);
        line.push_back(sm.mean);
        line.push_back(sm.ci95);
      }
    rows.push_back(line);
  }
  util::make_directory(opt.out_dir);
  util::write_csv(path_in(opt.out_dir, "e4_error.csv"),
                 {"t_s", "sod_e1", "sod_e1_ci", "sod_e2", "sod_e2_ci", "msod_e1", "msod_e1_ci", "msod_e2", "msod_e2_ci"}, rows, util::NonFinite::kMissing);
  // One run (the first seed): y1, x1, both estimates, the instants of (2b) sends and of losses.
  RunTrace ta, tc;
  simulate_run(model, config(0), opt.seed, &ta);
  simulate_run(model, config(1), opt.seed, &tc);
  std::vector<std::vector<double>> run;
  std::size_t time_sends = 0;
  for (std::size_t k = 0; k < tc.t_s.size(); ++k) {
    const bool ts = tc.cause[0][k] == static_cast<std::uint8_t>(node::SendCause::kTime);
    time_sends += ts ? 1 : 0;
    const bool sent = tc.cause[0][k] != static_cast<std::uint8_t>(node::SendCause::kNone);
    run.push_back({tc.t_s[k], tc.x[0][k], tc.y[0][k], ta.x_hat[0][k], tc.x_hat[0][k], ts ? tc.y[0][k] : kNaN,
                   sent && tc.arrived[0][k] == 0 ? tc.y[0][k] : kNaN});
  }
  // Send and loss markers are NaN where nothing happened (gnuplot draws no point there).
  util::write_csv(path_in(opt.out_dir, "e4_run.csv"), {"t_s", "x1", "y1", "xhat1_sod", "xhat1_msod", "time_send_y1", "lost_y1"}, run, util::NonFinite::kMissing);
  nlohmann::json j = {{"experiment", "E4"}, {"loss", loss}, {"seeds", opt.seeds}, {"first_seed", opt.seed},
                      {"n_t", {config(1).n_t[0], config(1).n_t[1]}}, {"bin_s", static_cast<double>(per_bin) * T},
                      {"time_rule_sends_node1_first_seed", time_sends}, {"files", {"e4_error.csv", "e4_run.csv"}}};
  // Mean error before and after 20 s (the paper's "slow tail").
  for (std::size_t a = 0; a < 2; ++a)
    for (std::size_t i = 0; i < kNodes; ++i) {
      double early = 0, late = 0;
      std::size_t ne = 0, nl = 0;
      for (const auto& line : rows) (line[0] < 20 ? (early += line[1 + 4 * a + 2 * i], ++ne) : (late += line[1 + 4 * a + 2 * i], ++nl));
      j["mean_error"][spec.approaches[a]]["e" + std::to_string(i + 1) + "_0_20s"] = ne ? early / static_cast<double>(ne) : 0.0;
      j["mean_error"][spec.approaches[a]]["e" + std::to_string(i + 1) + "_20s_end"] = nl ? late / static_cast<double>(nl) : 0.0;
    }
  if (opt.plots) {
    std::ostringstream gp;
    gp << util::gnuplot_png_terminal(1100, 1000) << "set output 'e4_traces.png'\n"
       << "set datafile separator ','\nset datafile missing 'nan'\nset grid\nset multiplot layout 3,1\nset xlabel 't (s)'\n"
       << "set logscale y\nset title 'E4: mean squared error of x1 over " << opt.seeds << " runs, xi = " << loss << " (0.5 s bins)'\n"
       << "plot 'e4_error.csv' using 1:2 skip 1 with lines lw 2 title '(a) SOD', '' using 1:6 skip 1 with lines lw 2 title '(c) modified SOD'\n"
       << "set title 'E4: mean squared error of x2'\n"
       << "plot 'e4_error.csv' using 1:4 skip 1 with lines lw 2 title '(a) SOD', '' using 1:8 skip 1 with lines lw 2 title '(c) modified SOD'\n"
       << "unset logscale y\nset title 'E4: one run (seed " << opt.seed << "): y1, its (2b) sends and lost packets of node 1'\n"
       << "plot 'e4_run.csv' using 1:3 skip 1 with lines lc rgb '#999999' title 'y1', '' using 1:5 skip 1 with lines lw 2 title 'x1 estimate (c)', "
       << "'' using 1:6 skip 1 with points pt 7 ps 0.8 title '(2b) send', '' using 1:7 skip 1 with points pt 2 ps 1.2 title 'lost'\n"
       << "unset multiplot\n";
    util::run_gnuplot(opt.out_dir, "e4_traces.gp", gp.str());
    j["files"].push_back("e4_traces.png");
  }
  return j;
}

}  // namespace oneshot::sod
