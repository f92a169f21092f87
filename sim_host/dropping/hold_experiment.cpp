/// @file hold_experiment.cpp
/// @brief E6 of the dropping study: the buffered filter against T_hold (current and anchor
///        error, corrections per step, the filter's bytes) at D = 1, 2.
#include <sstream>
#include <stdexcept>

#include "closed_loop.hpp"
#include "experiments.hpp"
#include "oneshot/engine/quantiles.hpp"
#include "oneshot/engine/sweep_statistics.hpp"
#include "oneshot/node/buffered_kalman.hpp"
#include "oneshot/number_format.hpp"
#include "oneshot/plant_structure.hpp"
#include "oneshot/sim/sweep_faults.hpp"
#include "oneshot/util/output_files.hpp"
#include "study_format.hpp"
#include "sweep_parts.hpp"

namespace oneshot::dropping {

std::size_t buffered_filter_bytes(int t_hold) {
  using Fmt = UniformFormat<double>;
  using St = DenseStructure<kN, kM, kP>;
  switch (t_hold) {
    case 1: return sizeof(node::BufferedKalman<Fmt, St, 1>);
    case 2: return sizeof(node::BufferedKalman<Fmt, St, 2>);
    case 3: return sizeof(node::BufferedKalman<Fmt, St, 3>);
    case 4: return sizeof(node::BufferedKalman<Fmt, St, 4>);
    case 5: return sizeof(node::BufferedKalman<Fmt, St, 5>);
    case 6: return sizeof(node::BufferedKalman<Fmt, St, 6>);
    case 7: return sizeof(node::BufferedKalman<Fmt, St, 7>);
    case 8: return sizeof(node::BufferedKalman<Fmt, St, 8>);
    default: throw std::invalid_argument("T_hold must be 1 ... 8");
  }
}

nlohmann::json run_hold(const DroppingPlant& plant, const StudyOptions& opt, int max_hold, const std::vector<double>& delays) {
  if (max_hold < 1 || max_hold > 8) throw std::invalid_argument("--max-hold must be 1 ... 8");
  engine::SweepSpec spec;
  spec.study = "dropping";
  spec.experiment = "hold";
  spec.approaches = {"buffered"};
  nlohmann::json sc = nlohmann::json::array();
  for (double d : delays)
    for (int t = 1; t <= max_hold; ++t) {
      spec.scenarios.push_back("T" + std::to_string(t) + "-D" + fmt_g(d));
      sc.push_back({{"T_hold", t}, {"D", d}, {"lambda", arrival_probability(t, d, opt.loss)},
                    {"filter_bytes", buffered_filter_bytes(t)}});
    }
  spec.first_seed = opt.seed;
  spec.seeds = opt.seeds;
  spec.metrics = {"err", "err_anchor", "trace_p", "trace_p_anchor", "gamma", "corrections", "cost", "over_delayed"};
  spec.config = {{"plant", plant.plant.name}, {"plant_digest", plant_digest(plant)}, {"loss", opt.loss},
                 {"steps", opt.steps}, {"scenarios", sc}};
  sim::add_fault_metrics(spec, opt.faults, "cost");
  const engine::SweepResults r = engine::run_sweep(
      spec, opt.shard, opt.threads,
      [&](std::size_t, std::size_t s, std::uint64_t seed) {
        const nlohmann::json& c = spec.config.at("scenarios").at(s);
        RunConfig rc;
        rc.t_hold = c.at("T_hold").get<int>();
        rc.mean_delay_periods = c.at("D").get<double>();
        rc.loss = opt.loss;
        rc.steps = opt.steps;
        rc.faults = opt.faults;
        const RunMetrics m = run_closed_loop(plant, rc, seed);
        return with_faults({m.err, m.err_anchor, m.trace_p, m.trace_p_anchor, m.gamma, m.corrections, m.cost,
                            m.over_delayed},
                           plant, rc, m, seed);
      },
      "dropping hold");
  return finish(r, opt, "hold", hold_outputs);
}

nlohmann::json hold_outputs(const engine::SweepResults& r, const std::string& out_dir, bool plots) {
  util::make_directory(out_dir);
  const nlohmann::json& cfg = r.spec.config;
  nlohmann::json j;
  j["experiment"] = "hold";
  j["steps"] = cfg.at("steps");
  j["seeds"] = r.spec.seeds;
  j["first_seed"] = r.spec.first_seed;
  if (cfg.contains("inject")) j["inject"] = cfg.at("inject");
  std::ostringstream md;
  md << "| D | T_hold | λ(T_hold) | γ freq | current \\|x − x̂(k\\|Y_k)\\|² median [10–90 %] | mean ± CI | anchor "
        "\\|x_n − x̂(n\\|n)\\|² median [10–90 %] | tr P_k median | predictions / corrections per step | filter bytes "
        "(double) |\n|---|---|---|---|---|---|---|---|---|---|\n";
  std::vector<std::vector<double>> csv;
  for (std::size_t s = 0; s < r.spec.scenarios.size(); ++s) {
    const nlohmann::json& c = cfg.at("scenarios").at(s);
    const int t = c.at("T_hold").get<int>();
    nlohmann::json js = c;
    for (const char* m : {"err", "err_anchor", "trace_p", "trace_p_anchor", "gamma", "corrections", "cost", "over_delayed"})
      js[m] = tail_json(engine::tail_summary(cell(r, 0, s, r.metric(m))));
    const engine::TailSummary te = engine::tail_summary(cell(r, 0, s, r.metric("err")));
    const engine::TailSummary ta = engine::tail_summary(cell(r, 0, s, r.metric("err_anchor")));
    const engine::TailSummary tp = engine::tail_summary(cell(r, 0, s, r.metric("trace_p")));
    const engine::TailSummary tg = engine::tail_summary(cell(r, 0, s, r.metric("gamma")));
    const engine::TailSummary tc = engine::tail_summary(cell(r, 0, s, r.metric("corrections")));
    js["predictions_per_step"] = t + 1;
    if (cfg.contains("inject")) js["faults"] = sim::fault_row(r, 0, s);
    j["per_cell"].push_back(js);
    md << "| " << fmt_g(c.at("D").get<double>()) << " | " << t << " | " << fmt_f(c.at("lambda").get<double>(), 4) << " | "
       << fmt_f(tg.mean.mean, 4) << " | " << band_md(te) << " | " << mean_md(te) << " | " << band_md(ta) << " | "
       << fmt_g(tp.median) << " | " << t + 1 << " / " << fmt_f(tc.mean.mean, 2) << " | "
       << c.at("filter_bytes").get<std::size_t>() << " |\n";
    csv.push_back({c.at("D").get<double>(), static_cast<double>(t), te.median, te.p10, te.p90, ta.median, ta.p10, ta.p90,
                   tc.mean.mean});
  }
  j["markdown"] = md.str();
  if (cfg.contains("inject")) j["markdown_faults"] = sim::fault_markdown(r);
  util::write_csv(util::path_in(out_dir, "hold.csv"),
                 {"D", "T_hold", "err_median", "err_p10", "err_p90", "anchor_median", "anchor_p10", "anchor_p90",
                  "corrections"},
                 csv, util::NonFinite::kMissing);
  engine::write_runs_csv(r, util::path_in(out_dir, "hold_runs.csv"), util::NonFinite::kMissing);
  if (plots) {
    std::ostringstream g;
    g << util::gnuplot_png_terminal(1000, 550) << "set output 'hold.png'\n"
         "set datafile separator ','\nset grid\nset logscale y\nset xlabel 'T_hold (periods)'\n"
         "set ylabel 'time-mean squared error'\nset key top right\n"
         "set title 'E6: current and anchor error against T_hold (median, 10-90 % band)'\n"
         "plot 'hold.csv' skip 1 using ($1==1?$2:1/0):3:4:5 with yerrorlines lw 2 title 'current, D = 1', "
         "'' skip 1 using ($1==2?$2+0.05:1/0):3:4:5 with yerrorlines lw 2 title 'current, D = 2', "
         "'' skip 1 using ($1==1?$2+0.1:1/0):6:7:8 with yerrorlines dt 2 title 'anchor, D = 1', "
         "'' skip 1 using ($1==2?$2+0.15:1/0):6:7:8 with yerrorlines dt 2 title 'anchor, D = 2'\n";
    util::run_gnuplot(out_dir, "hold.gp", g.str());
  }
  j["files"] = {"hold.csv", "hold_runs.csv", "hold.png"};
  return j;
}

}  // namespace oneshot::dropping
