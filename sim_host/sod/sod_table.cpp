/// @file sod_table.cpp
/// @brief E3 a–c: the table of configurations × loss rates as an engine sweep (see
///        sod_experiments.hpp), shardable and merged by the registered summarizer.
#include <array>
#include <cmath>
#include <fstream>
#include <sstream>

#include "oneshot/engine/random_stream.hpp"
#include "oneshot/engine/sweep_statistics.hpp"
#include "oneshot/util/number_text.hpp"
#include "oneshot/util/output_files.hpp"
#include "oneshot/util/statistics.hpp"
#include "sod_experiments.hpp"

namespace oneshot::sod {
namespace {

/// The table's configurations, in table order.
struct Configuration {
  const char* name;
  const char* description;
  SenderKind sender;
  FilterKind filter;
};
constexpr Configuration kConfigurations[] = {
    {"sod-held", "(a) SOD + plain SOD filter (held value, R + dy^2/3)", SenderKind::kSod, FilterKind::kHeld},
    {"sod-kf", "(b) SOD + Kalman filter that only predicts when nothing arrives", SenderKind::kSod, FilterKind::kPredictOnly},
    {"msod", "(c) modified SOD (dt* of the design) + section-4 filter", SenderKind::kModifiedSod, FilterKind::kHeld},
    {"periodic", "periodic, every sample + Kalman filter (predicts over losses): the floor", SenderKind::kPeriodic,
     FilterKind::kPredictOnly},
};
const std::vector<std::string> kMetrics = {"e1", "e2", "e1_tail", "e2_tail", "nees", "sends1", "sends2",
                                           "time_sends1", "time_sends2", "lost1", "lost2", "detected1", "detected2"};

/// Per-run counters of a faulted table (RunResult): faults injected, frames refused, estimator resets.
const std::vector<std::string> kFaultMetrics = {"injected", "corrupt", "refused_non_finite", "refused_sequence",
                                                "estimator_resets"};

using util::path_in;
std::string f4(double v) { return util::format_g(v, 4); }
using util::mean_ci_json;

}  // namespace

nlohmann::json run_table(const SodModel& model, const StudyOptions& opt) {
  if (opt.seeds < 2) throw std::invalid_argument("sod table needs at least 2 seeds for confidence intervals");
  const MeanGap g = measure_mean_gap(model, opt, opt.delta_y);
  engine::SweepSpec spec;
  spec.study = "sod";
  spec.experiment = "table";
  for (const Configuration& c : kConfigurations) spec.approaches.push_back(c.name);
  nlohmann::json scen = nlohmann::json::array();
  std::vector<std::array<std::uint32_t, kNodes>> n_t;
  for (double xi : opt.losses) {
    spec.scenarios.push_back("xi=" + f4(xi));
    std::array<std::uint32_t, kNodes> nt{0, 0};
    nlohmann::json s = {{"loss", xi}};
    if (xi > 0) {
      const DeltaTDesign d = design_at(model, opt, g, opt.delta_y, xi);
      for (std::size_t i = 0; i < kNodes; ++i) nt[i] = d.node[i].bounded ? d.node[i].n_t : 0;
    }
    for (std::size_t i = 0; i < kNodes; ++i) s["n_t"].push_back(nt[i]);
    scen.push_back(s);
    n_t.push_back(nt);
  }
  spec.first_seed = opt.seed;
  spec.seeds = opt.seeds;
  spec.metrics = kMetrics;
  spec.config = {{"plant", model.plant_name},
                 {"delta_y", opt.delta_y}, {"mu", opt.mu}, {"amplitude", opt.amplitude}, {"steps", opt.steps},
                 {"period_s", model.period_s()},
                 {"mean_gap_s", {g.mean_s[0], g.mean_s[1]}},
                 {"scenarios", scen}};
  if (!opt.faults.empty()) {  // only then: the clean table's spec (and its shards) stay as they were
    spec.config["inject"] = opt.faults.text;
    for (const auto& m : kFaultMetrics) spec.metrics.push_back(m);
  }
  const engine::SweepResults r = engine::run_sweep(spec, opt.shard, opt.threads,
      [&](std::size_t a, std::size_t s, std::uint64_t seed) {
        RunConfig cfg;
        cfg.sender = kConfigurations[a].sender;
        cfg.filter = kConfigurations[a].filter;
        cfg.delta_y[0] = cfg.delta_y[1] = opt.delta_y;
        cfg.n_t[0] = n_t[s][0];
        cfg.n_t[1] = n_t[s][1];
        cfg.loss = opt.losses[s];
        cfg.amplitude = opt.amplitude;
        cfg.steps = opt.steps;
        cfg.faults = opt.faults;
        const RunResult x = simulate_run(model, cfg, seed);
        std::vector<double> v{x.e[0], x.e[1], x.e_tail[0], x.e_tail[1], x.nees, x.sends[0], x.sends[1],
                              x.time_sends[0], x.time_sends[1], x.lost[0], x.lost[1], x.detected[0], x.detected[1]};
        if (!opt.faults.empty())
          v.insert(v.end(), {static_cast<double>(x.injected.injected()), x.corrupt, x.refused_non_finite, x.refused_sequence,
                             x.estimator_resets});
        return v;
      }, "sod table");
  if (!opt.shard.whole()) return engine::write_shard_file(r, opt.out_dir, "table", opt.shard);
  return table_outputs(r, opt.out_dir, opt.plots);
}

nlohmann::json table_outputs(const engine::SweepResults& results, const std::string& out_dir, bool plots) {
  util::make_directory(out_dir);
  const engine::SweepSpec& spec = results.spec;
  const std::size_t na = spec.approaches.size(), ns = spec.scenarios.size(), seeds = spec.seeds;
  auto series = [&](std::size_t a, std::size_t s, const std::string& m) {
    std::vector<double> v;
    const std::size_t mi = results.metric(m);
    for (std::size_t k = 0; k < seeds; ++k) v.push_back(results.at(a, s, k, mi));
    return v;
  };
  auto stat = [&](std::size_t a, std::size_t s, const std::string& m) { return util::summarize(series(a, s, m)); };
  nlohmann::json j = {{"experiment", "E3 table"}, {"config", spec.config}, {"seeds", seeds}, {"first_seed", spec.first_seed}};
  if (spec.config.contains("inject")) j["inject"] = spec.config.at("inject");
  std::ostringstream md;
  md << "| configuration | xi | packets 1 | packets 2 | (2b) 1 | (2b) 2 | lost 1 | lost 2 | e1 (95 % CI) | e2 (95 % CI) | e1 20-50 s | NEES (2 = consistent) |\n"
        "|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  std::vector<std::vector<double>> csv;
  for (std::size_t a = 0; a < na; ++a) {
    for (std::size_t s = 0; s < ns; ++s) {
      const double xi = spec.config.at("scenarios").at(s).at("loss").get<double>();
      nlohmann::json row = {{"configuration", spec.approaches[a]}, {"description", kConfigurations[a].description}, {"loss", xi}};
      if (kConfigurations[a].sender == SenderKind::kModifiedSod) row["n_t"] = spec.config.at("scenarios").at(s).at("n_t");
      for (int i = 1; i <= 2; ++i) {
        const std::string n = std::to_string(i);
        row["packets"].push_back(mean_ci_json(stat(a, s, "sends" + n)));
        row["time_rule_sends"].push_back(mean_ci_json(stat(a, s, "time_sends" + n)));
        row["losses"].push_back(mean_ci_json(stat(a, s, "lost" + n)));
        row["detected_losses"].push_back(mean_ci_json(stat(a, s, "detected" + n)));
        row["e"].push_back(mean_ci_json(stat(a, s, "e" + n)));
        row["e_tail_20_50s"].push_back(mean_ci_json(stat(a, s, "e" + n + "_tail")));
      }
      row["nees"] = mean_ci_json(stat(a, s, "nees"));
      if (spec.config.contains("inject"))
        for (const auto& m : kFaultMetrics) row["faults"][m] = mean_ci_json(stat(a, s, m));
      j["rows"].push_back(row);
      const auto e1 = stat(a, s, "e1"), e2 = stat(a, s, "e2"), t1 = stat(a, s, "e1_tail"), nees = stat(a, s, "nees");
      md << "| " << spec.approaches[a] << " | " << xi << " | " << f4(stat(a, s, "sends1").mean) << " | "
         << f4(stat(a, s, "sends2").mean) << " | " << f4(stat(a, s, "time_sends1").mean) << " | "
         << f4(stat(a, s, "time_sends2").mean) << " | " << f4(stat(a, s, "lost1").mean) << " | "
         << f4(stat(a, s, "lost2").mean) << " | " << f4(e1.mean) << " ± " << f4(e1.ci95) << " | " << f4(e2.mean) << " ± "
         << f4(e2.ci95) << " | " << f4(t1.mean) << " ± " << f4(t1.ci95) << " | " << f4(nees.mean) << " ± " << f4(nees.ci95) << " |\n";
      csv.push_back({static_cast<double>(a), xi, e1.mean, e1.ci95, e2.mean, e2.ci95, nees.mean, nees.ci95,
                     stat(a, s, "sends1").mean + stat(a, s, "sends2").mean});
    }
  }
  // Paired differences per loss rate (every configuration of a seed sees the same plant,
  // noise and loss draws): (c) − (a), (c) − (b), (b) − (a) on e1, e2.
  std::ostringstream pd;
  pd << "| pair | xi | e1 difference (95 % CI) | e2 difference (95 % CI) |\n|---|---|---|---|\n";
  const std::size_t pairs[][2] = {{2, 0}, {2, 1}, {1, 0}};
  for (const auto& p : pairs) {
    if (p[0] >= na || p[1] >= na) continue;
    for (std::size_t s = 0; s < ns; ++s) {
      const double xi = spec.config.at("scenarios").at(s).at("loss").get<double>();
      nlohmann::json e = {{"pair", spec.approaches[p[0]] + " - " + spec.approaches[p[1]]}, {"loss", xi}};
      pd << "| " << spec.approaches[p[0]] << " − " << spec.approaches[p[1]] << " | " << xi;
      for (const char* m : {"e1", "e2"}) {
        const auto x = series(p[0], s, m), y = series(p[1], s, m);
        std::vector<double> d(x.size());
        for (std::size_t k = 0; k < x.size(); ++k) d[k] = x[k] - y[k];
        const util::Summary sd = util::summarize(d);
        e[m] = mean_ci_json(sd);
        pd << " | " << f4(sd.mean) << " ± " << f4(sd.ci95);
      }
      pd << " |\n";
      j["paired_differences"].push_back(e);
    }
  }
  // Plain SOD's decisions do not depend on ξ: its packets per seed must be the same at every ξ.
  bool identical = true;
  for (std::size_t k = 0; k < seeds; ++k)
    for (std::size_t s = 1; s < ns; ++s)
      for (const char* m : {"sends1", "sends2"})
        if (results.at(0, s, k, results.metric(m)) != results.at(0, 0, k, results.metric(m))) identical = false;
  j["sod_packets_identical_across_loss"] = identical;
  j["markdown"] = md.str();
  j["markdown_paired"] = pd.str();
  {
    std::ofstream out(path_in(out_dir, "table.md"));
    out << "E3 table: " << seeds << " seeds per cell\n\n" << md.str() << "\nPaired differences:\n\n" << pd.str();
  }
  util::write_csv(path_in(out_dir, "table.csv"),
                 {"configuration_index", "loss", "e1", "e1_ci95", "e2", "e2_ci95", "nees", "nees_ci95", "packets"}, csv);
  engine::write_runs_csv(results, path_in(out_dir, "table_runs.csv"));
  j["files"] = {"table.md", "table.csv", "table_runs.csv"};
  if (plots) {
    std::ostringstream g;
    g << util::gnuplot_png_terminal(1100, 500) << "set output 'table.png'\n"
      << "set datafile separator ','\nset grid\nset multiplot layout 1,2\nset xlabel 'loss rate xi'\nset key top left\n"
      << "set offsets 0.01, 0.01, 0, 0\n";
    for (int node = 1; node <= 2; ++node) {
      g << "set title 'E3: e_" << node << " with 95 % CI'\nset ylabel 'e_" << node << "'\nset logscale y\nplot ";
      for (std::size_t a = 0; a < na; ++a)
        g << (a ? ", " : "") << "'table.csv' using 2:($1 == " << a << " ? $" << 1 + 2 * node << " : 1/0):" << 2 + 2 * node
          << " skip 1 with yerrorlines title '" << spec.approaches[a] << "'";
      g << "\n";
    }
    g << "unset multiplot\n";
    util::run_gnuplot(out_dir, "table.gp", g.str());
    j["files"].push_back("table.png");
  }
  return j;
}

}  // namespace oneshot::sod
