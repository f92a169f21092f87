/// @file experiments.cpp
/// @brief E1 (arrival) and E4/E5 (closed loop) sweeps of the dropping study (E6: hold_experiment.cpp).
#include "experiments.hpp"

#include <cmath>
#include <cstdio>
#include <sstream>
#include <stdexcept>

#include "closed_loop.hpp"
#include "oneshot/engine/quantiles.hpp"
#include "oneshot/engine/random_stream.hpp"
#include "oneshot/engine/sweep_statistics.hpp"
#include "oneshot/sim/sweep_faults.hpp"
#include "oneshot/node/buffered_kalman.hpp"
#include "oneshot/number_format.hpp"
#include "oneshot/plant_structure.hpp"
#include "oneshot/util/output_files.hpp"
#include "study_format.hpp"
#include "sweep_parts.hpp"

namespace oneshot::dropping {
namespace {

using util::path_in;

const char* const kClosedLoopApproaches[] = {"buffered", "buffered-bernoulli", "unaware-R0.05", "unaware-R2.5"};

}  // namespace

// ---------------------------------------------------------------- E1: arrival probability

nlohmann::json run_arrival(const StudyOptions& opt) {
  engine::SweepSpec spec;
  spec.study = "dropping";
  spec.experiment = "arrival";
  spec.approaches = {"pipeline"};
  const std::vector<double> delays{0.5, 1, 2, 3};
  nlohmann::json sc = nlohmann::json::array();
  for (double d : delays)
    for (int t = 1; t <= 8; ++t) {
      spec.scenarios.push_back("D" + fmt_g(d) + "-T" + std::to_string(t));
      sc.push_back({{"D", d}, {"T_hold", t}});
    }
  spec.first_seed = opt.seed;
  spec.seeds = opt.seeds;
  spec.metrics = {"gamma"};
  spec.config = {{"loss", opt.loss}, {"steps", opt.steps}, {"scenarios", sc}};
  const engine::SweepResults r = engine::run_sweep(
      spec, opt.shard, opt.threads,
      [&](std::size_t, std::size_t s, std::uint64_t seed) {
        const nlohmann::json& c = spec.config.at("scenarios").at(s);
        return std::vector<double>{
            simulate_gamma_frequency(c.at("T_hold").get<int>(), c.at("D").get<double>(), opt.loss, opt.steps, seed)};
      },
      "dropping arrival");
  return finish(r, opt, "arrival", arrival_outputs);
}

nlohmann::json arrival_outputs(const engine::SweepResults& r, const std::string& out_dir, bool plots) {
  util::make_directory(out_dir);
  const nlohmann::json& cfg = r.spec.config;
  const double loss = cfg.at("loss").get<double>();
  const engine::SweepSummary sm = engine::summarize_metric(r, 0, 0);
  nlohmann::json rows = nlohmann::json::array();
  std::vector<std::vector<double>> csv;
  std::size_t inside = 0;
  std::ostringstream md;
  md << "| D | T_hold | λ(T_hold) closed form | simulated γ frequency | 95 % CI | inside CI |\n|---|---|---|---|---|---|\n";
  for (std::size_t s = 0; s < r.spec.scenarios.size(); ++s) {
    const nlohmann::json& c = cfg.at("scenarios").at(s);
    const double d = c.at("D").get<double>();
    const int t = c.at("T_hold").get<int>();
    const double lam = arrival_probability(t, d, loss);
    const util::Summary& v = sm.per_scenario[0][s];
    const bool in = std::fabs(v.mean - lam) <= v.ci95;
    inside += in ? 1 : 0;
    rows.push_back({{"D", d}, {"T_hold", t}, {"lambda", lam}, {"simulated", v.mean}, {"ci95", v.ci95}, {"inside_ci", in}});
    csv.push_back({d, static_cast<double>(t), lam, v.mean, v.ci95});
    md << "| " << fmt_g(d) << " | " << t << " | " << fmt_f(lam, 5) << " | " << fmt_f(v.mean, 5) << " | ± "
       << fmt_f(v.ci95, 5) << " | " << (in ? "yes" : "no") << " |\n";
  }
  nlohmann::json j;
  j["experiment"] = "arrival";
  j["loss"] = loss;
  j["steps"] = cfg.at("steps");
  j["seeds"] = r.spec.seeds;
  j["first_seed"] = r.spec.first_seed;
  j["table"] = rows;
  j["inside_ci"] = inside;
  j["cells"] = r.spec.scenarios.size();
  j["markdown"] = md.str();
  util::write_csv(path_in(out_dir, "arrival.csv"), {"D", "T_hold", "lambda", "simulated", "ci95"}, csv);
  // Poisson pmf with the loss factor (Fig 2a).
  std::vector<std::vector<double>> pmf;
  for (int t = 0; t <= 10; ++t)
    pmf.push_back({static_cast<double>(t), (1 - loss) * poisson_pmf(t, 0.5), (1 - loss) * poisson_pmf(t, 1),
                   (1 - loss) * poisson_pmf(t, 2), (1 - loss) * poisson_pmf(t, 3)});
  util::write_csv(path_in(out_dir, "arrival_pmf.csv"), {"t", "D0.5", "D1", "D2", "D3"}, pmf);
  if (plots) {
    std::ostringstream g;
    g << util::gnuplot_png_terminal(1200, 500) << "set output 'arrival.png'\n"
         "set datafile separator ','\nset multiplot layout 1,2\nset grid\n"
         "set title '(1 - loss) x Poisson pmf of the delay (whole periods)'\nset xlabel 'delay t (periods)'\n"
         "set ylabel 'probability'\nset style data linespoints\n"
         "plot for [c=2:5] 'arrival_pmf.csv' using 1:c skip 1 title columnhead(c)\n"
         "set title 'lambda(T_hold): closed form (lines), simulated gamma frequency (points, 95 % CI)'\n"
         "set xlabel 'T_hold (periods)'\nset ylabel 'lambda'\nset yrange [0:1]\nset key bottom right\n"
         "plot for [i=0:3] 'arrival.csv' skip 1 every ::(8*i)::(8*i+7) using 2:3 with lines lw 2 title sprintf('D = %s', word('0.5 1 2 3', i+1)), "
         "for [i=0:3] 'arrival.csv' skip 1 every ::(8*i)::(8*i+7) using 2:4:5 with yerrorbars pt 7 ps 0.6 lc rgb 'black' notitle\n"
         "unset multiplot\n";
    util::run_gnuplot(out_dir, "arrival.gp", g.str());
  }
  j["files"] = {"arrival.csv", "arrival_pmf.csv", "arrival.png"};
  return j;
}

// ---------------------------------------------------------------- E4/E5: closed loop

nlohmann::json run_closed_loop_experiment(const DroppingPlant& plant, const StudyOptions& opt,
                                          const std::vector<double>& lambdas) {
  engine::SweepSpec spec;
  spec.study = "dropping";
  spec.experiment = "closed-loop";
  for (const char* a : kClosedLoopApproaches) spec.approaches.emplace_back(a);
  nlohmann::json sc = nlohmann::json::array();
  for (double l : lambdas) {
    spec.scenarios.push_back("lambda" + fmt_g(l));
    sc.push_back({{"lambda", l}, {"D", delay_for_lambda(l, opt.loss)}});
  }
  spec.first_seed = opt.seed;
  spec.seeds = opt.seeds;
  spec.metrics = {"err", "err_anchor", "trace_p", "trace_p_anchor", "gamma", "cost", "reordered", "failed",
                  "err_shadow_R0.05", "err_shadow_R2.5"};
  spec.config = {{"plant", plant.plant.name}, {"plant_digest", plant_digest(plant)}, {"loss", opt.loss},
                 {"steps", opt.steps}, {"t_hold", 1}, {"scenarios", sc}};
  sim::add_fault_metrics(spec, opt.faults, "cost");
  const engine::SweepResults r = engine::run_sweep(
      spec, opt.shard, opt.threads,
      [&](std::size_t a, std::size_t s, std::uint64_t seed) {
        RunConfig c;
        c.t_hold = 1;
        c.steps = opt.steps;
        c.loss = opt.loss;
        c.mean_delay_periods = delay_for_lambda(lambdas[s], opt.loss);
        c.bernoulli_lambda = lambdas[s];
        c.channel = a == 1 ? ChannelKind::kBernoulli : ChannelKind::kNetwork;
        c.estimator = a >= 2 ? EstimatorKind::kUnaware : EstimatorKind::kBuffered;
        c.unaware_r = a == 2 ? 0.05 : 2.5;
        c.faults = opt.faults;
        const RunMetrics m = run_closed_loop(plant, c, seed);
        return with_faults({m.err, m.err_anchor, m.trace_p, m.trace_p_anchor, m.gamma, m.cost, m.reordered,
                            m.failed ? 1.0 : 0.0, m.err_shadow_small_r, m.err_shadow_nominal_r},
                           plant, c, m, seed);
      },
      "dropping closed-loop");
  nlohmann::json j = finish(r, opt, "closed-loop", closed_loop_outputs);
  if (opt.shard.whole()) {
    // One traced run per λ (first seed): y and C x̂ of the buffered filter (Figs 5–6).
    std::vector<std::vector<double>> rows;
    for (std::size_t s = 0; s < lambdas.size(); ++s) {
      RunConfig c;
      c.steps = opt.steps;
      c.loss = opt.loss;
      c.mean_delay_periods = delay_for_lambda(lambdas[s], opt.loss);
      c.trace = true;
      c.faults = opt.faults;
      const RunMetrics m = run_closed_loop(plant, c, opt.seed);
      for (std::size_t k = 0; k < opt.steps; ++k)
        rows.push_back({static_cast<double>(s), static_cast<double>(k) * plant.plant.period_us * 1e-6, m.trace.y[k],
                        m.trace.cx[k], m.trace.cxhat[k], m.trace.trace_p[k], m.trace.err[k]});
    }
    util::write_csv(path_in(opt.out_dir, "closed_loop_trace.csv"), {"scenario", "t_s", "y", "Cx", "Cxhat", "trace_p", "err"},
                   rows, util::NonFinite::kMissing);
    if (opt.plots) {
      std::ostringstream g;
      g << util::gnuplot_png_terminal(1200, static_cast<int>(300 * lambdas.size()), 10)
        << "set output 'closed_loop_trace.png'\nset datafile separator ','\nset multiplot layout " << lambdas.size()
        << ",1\nset grid\nset xlabel 't (s)'\n";
      for (std::size_t s = 0; s < lambdas.size(); ++s)
        g << "set title 'lambda = " << fmt_g(lambdas[s]) << " (pipeline, T_hold = 1, seed " << opt.seed
          << "): y (grey), C x (blue), C xhat (red)'\nplot 'closed_loop_trace.csv' skip 1 every ::" << s * opt.steps
          << "::" << (s + 1) * opt.steps - 1 << " using 2:3 with lines lc rgb '#bbbbbb' title 'y', '' skip 1 every ::"
          << s * opt.steps << "::" << (s + 1) * opt.steps - 1
          << " using 2:4 with lines lc rgb '#1f77b4' title 'C x', '' skip 1 every ::" << s * opt.steps
          << "::" << (s + 1) * opt.steps - 1 << " using 2:5 with lines lc rgb '#d62728' title 'C xhat'\n";
      g << "unset multiplot\n";
      util::run_gnuplot(opt.out_dir, "closed_loop_trace.gp", g.str());
    }
    j["files"].push_back("closed_loop_trace.csv");
    j["files"].push_back("closed_loop_trace.png");
  }
  return j;
}

nlohmann::json closed_loop_outputs(const engine::SweepResults& r, const std::string& out_dir, bool plots) {
  util::make_directory(out_dir);
  const nlohmann::json& cfg = r.spec.config;
  const std::size_t na = r.spec.approaches.size(), ns = r.spec.scenarios.size();
  const std::vector<std::string> shown{"err", "err_anchor", "trace_p", "trace_p_anchor", "gamma", "cost"};
  nlohmann::json j;
  j["experiment"] = "closed-loop";
  j["steps"] = cfg.at("steps");
  j["seeds"] = r.spec.seeds;
  j["first_seed"] = r.spec.first_seed;
  j["loss"] = cfg.at("loss");
  if (cfg.contains("inject")) j["inject"] = cfg.at("inject");
  std::ostringstream md;
  md << "| λ | estimator | \\|x − x̂(k\\|Y_k)\\|² median [10–90 %] | mean ± 95 % CI | tr P_k median [10–90 %] | mean ± CI | "
        "anchor \\|x_n − x̂(n\\|n)\\|² median | γ freq | paired Δ err vs buffered (median of per-seed ratio) |\n"
        "|---|---|---|---|---|---|---|---|---|\n";
  std::vector<std::vector<double>> csv;
  std::size_t failed = 0;
  for (std::size_t s = 0; s < ns; ++s) {
    const nlohmann::json& c = cfg.at("scenarios").at(s);
    nlohmann::json js = {{"lambda", c.at("lambda")}, {"D", c.at("D")}};
    const std::vector<double> ref = cell(r, 0, s, r.metric("err"));
    for (std::size_t a = 0; a < na; ++a) {
      nlohmann::json ja;
      for (const std::string& m : shown) ja[m] = tail_json(engine::tail_summary(cell(r, a, s, r.metric(m))));
      for (double f : cell(r, a, s, r.metric("failed"))) failed += f != 0 ? 1 : 0;
      const std::vector<double> e = cell(r, a, s, r.metric("err"));
      std::vector<double> ratio(e.size()), diff(e.size());
      for (std::size_t k = 0; k < e.size(); ++k) {
        ratio[k] = e[k] / ref[k];
        diff[k] = e[k] - ref[k];
      }
      const engine::TailSummary tr = engine::tail_summary(ratio);
      const util::Summary dd = util::summarize(diff);
      ja["paired_err_ratio_to_buffered"] = tail_json(tr);
      // Null where the differences overflow (a diverging baseline): the median ratio beside it stays defined.
      ja["paired_err_difference_to_buffered"] = {{"mean", num(dd.mean)}, {"ci95", num(dd.ci95)}};
      if (cfg.contains("inject")) ja["faults"] = sim::fault_row(r, a, s);
      js["approaches"][r.spec.approaches[a]] = ja;
      const engine::TailSummary te = engine::tail_summary(e);
      const engine::TailSummary tp = engine::tail_summary(cell(r, a, s, r.metric("trace_p")));
      const engine::TailSummary ta = engine::tail_summary(cell(r, a, s, r.metric("err_anchor")));
      const engine::TailSummary tg = engine::tail_summary(cell(r, a, s, r.metric("gamma")));
      md << "| " << c.at("lambda").get<double>() << " | " << r.spec.approaches[a] << " | " << band_md(te) << " | "
         << mean_md(te) << " | " << band_md(tp) << " | " << mean_md(tp) << " | "
         << (std::isnan(ta.median) ? std::string("—") : fmt_g(ta.median)) << " | "
         << (tg.mean.n == 0 ? std::string("—") : fmt_f(tg.mean.mean, 4)) << " | "
         << (a == 0 ? std::string("—") : band_md(tr)) << " |\n";
      csv.push_back({c.at("lambda").get<double>(), static_cast<double>(a), te.median, te.p10, te.p90, te.mean.mean,
                     te.mean.ci95, tp.median, tp.p10, tp.p90, tp.mean.mean, tp.mean.ci95});
    }
    j["per_lambda"].push_back(js);
  }
  j["failed_runs"] = failed;
  // E5: the delay-unaware KF beside the buffered filter on the same trajectory (shadow), and
  // closing the loop itself (diverged: time-mean error above 1e100 or not finite).
  std::ostringstream m5;
  m5 << "| λ | buffered \\|x − x̂\\|² median [10–90 %] | unaware R = 0.05 (shadow) | per-seed ratio to buffered | "
        "unaware R = 2.5 (shadow) | per-seed ratio to buffered | unaware closing the loop: runs diverged (R = 0.05 / 2.5) |\n"
        "|---|---|---|---|---|---|---|\n";
  for (std::size_t s = 0; s < ns; ++s) {
    const nlohmann::json& c = cfg.at("scenarios").at(s);
    const std::vector<double> e = cell(r, 0, s, r.metric("err"));
    m5 << "| " << c.at("lambda").get<double>() << " | " << band_md(engine::tail_summary(e));
    nlohmann::json js;
    for (const char* name : {"err_shadow_R0.05", "err_shadow_R2.5"}) {
      const std::vector<double> sh = cell(r, 0, s, r.metric(name));
      std::vector<double> ratio(sh.size());
      for (std::size_t k = 0; k < sh.size(); ++k) ratio[k] = sh[k] / e[k];
      const engine::TailSummary ts = engine::tail_summary(sh), tr = engine::tail_summary(ratio);
      js[name] = tail_json(ts);
      js[std::string(name) + "_ratio_to_buffered"] = tail_json(tr);
      m5 << " | " << band_md(ts) << " | " << band_md(tr);
    }
    std::size_t div[2] = {0, 0};
    for (std::size_t a = 2; a < 4 && a < na; ++a)
      for (double v : cell(r, a, s, r.metric("err"))) div[a - 2] += (!std::isfinite(v) || v > 1e100) ? 1U : 0U;
    js["unaware_closed_loop_diverged"] = {div[0], div[1]};
    m5 << " | " << div[0] << " / " << div[1] << " of " << r.spec.seeds << " |\n";
    j["e5"].push_back(js);
  }
  j["markdown_e5"] = m5.str();
  j["markdown"] = md.str();
  if (cfg.contains("inject")) j["markdown_faults"] = sim::fault_markdown(r);
  util::write_csv(path_in(out_dir, "closed_loop.csv"),
                 {"lambda", "approach", "err_median", "err_p10", "err_p90", "err_mean", "err_ci95", "trp_median", "trp_p10",
                  "trp_p90", "trp_mean", "trp_ci95"},
                 csv, util::NonFinite::kMissing);
  engine::write_runs_csv(r, path_in(out_dir, "closed_loop_runs.csv"), util::NonFinite::kMissing);
  if (plots) {
    std::ostringstream g;
    g << util::gnuplot_png_terminal(1200, 500) << "set output 'closed_loop.png'\n"
         "set datafile separator ','\nset multiplot layout 1,2\nset grid\nset logscale y\nset format y '10^{%L}'\n"
         "set xlabel 'lambda'\nset key top right\nset offsets 0.01,0.01,0,0\n"
         "set title 'time-mean |x - xhat(k|Y_k)|^2: median and 10-90 % band'\n"
         "plot for [a=0:" << na - 1 << "] 'closed_loop.csv' skip 1 using ($1+0.004*a):($2==a?$3:1/0):4:5 with yerrorlines "
         "title word('" << "buffered buffered-bernoulli unaware-R0.05 unaware-R2.5" << "', a+1)\n"
         "set title 'time-mean tr P_k: median and 10-90 % band'\n"
         "plot for [a=0:" << na - 1 << "] 'closed_loop.csv' skip 1 using ($1+0.004*a):($2==a?$8:1/0):9:10 with yerrorlines "
         "title word('buffered buffered-bernoulli unaware-R0.05 unaware-R2.5', a+1)\nunset multiplot\n";
    util::run_gnuplot(out_dir, "closed_loop.gp", g.str());
  }
  j["files"] = {"closed_loop.csv", "closed_loop_runs.csv", "closed_loop.png"};
  return j;
}

}  // namespace oneshot::dropping
