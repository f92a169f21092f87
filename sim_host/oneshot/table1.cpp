/// @file table1.cpp
/// @brief Table I on the engine's sweep (see table1.hpp).
#include "table1.hpp"

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <sstream>
#include <stdexcept>

#include "oneshot/design/design_report.hpp"
#include "oneshot/engine/random_stream.hpp"
#include "oneshot/engine/sweep_statistics.hpp"
#include "oneshot/util/output_files.hpp"

namespace oneshot::sim {
namespace {

std::string hex64(std::uint64_t v) {
  char b[20];
  std::snprintf(b, sizeof b, "%016llx", static_cast<unsigned long long>(v));
  return b;
}

using util::path_in;

}  // namespace

engine::SweepSpec table1_spec(const SimContext& ctx, const CommonOptions& opt, const std::vector<Scenario>& scenarios,
                              std::size_t seeds) {
  engine::SweepSpec spec;
  spec.study = "oneshot";
  spec.experiment = "table1";
  // Approaches the plant cannot run (E without a deadbeat observer) are left out of the sweep
  // and reported unavailable with the design step's reason.
  nlohmann::json unavailable = nlohmann::json::object();
  for (Approach a : kAllApproaches) {
    if (approach_available(ctx, a)) {
      spec.approaches.emplace_back(1, info(a).letter);
    } else {
      unavailable[std::string(1, info(a).letter)] = "no deadbeat observer: " + ctx.design().deadbeat_unavailable_reason;
    }
  }
  for (const Scenario& s : scenarios) spec.scenarios.push_back(s.name);
  spec.first_seed = opt.seed;
  spec.seeds = seeds;
  spec.metrics = {"cost", "saturated"};
  nlohmann::json sc = nlohmann::json::array();
  for (const Scenario& s : scenarios) {
    sc.push_back({{"name", s.name},
                  {"jitter", s.jitter.describe()},
                  {"amplitude_volts", s.amplitude_volts},
                  {"change_period_s", s.change_period_s},
                  {"duration_s", s.duration_s}});
  }
  spec.config = {{"plant", ctx.plant().name},
                 {"plant_digest", hex64(engine::stream_id(design::design_json(ctx.plant(), ctx.design()).dump()))},
                 {"number_format", to_string(opt.format)},
                 {"discretizer", to_string(opt.discretizer)},
                 {"noise_model", opt.noise == NoiseModel::kExact ? "exact" : "constant"},
                 {"pwm_update", opt.board.update == PwmUpdate::kNextPeriod ? "period" : "immediate"},
                 {"process_noise", opt.board.process_noise},
                 {"scenarios", sc}};
  if (!unavailable.empty()) spec.config["unavailable_approaches"] = unavailable;
  return spec;
}

engine::SweepResults table1_sweep(const SimContext& ctx, const CommonOptions& opt,
                                  const std::vector<Scenario>& scenarios, std::size_t seeds,
                                  const engine::Shard& shard, double* wall_time_s) {
  if (seeds < 2) throw std::invalid_argument("table1 needs at least 2 seeds for confidence intervals");
  for (const Scenario& s : scenarios) validate_scenario(s, ctx.plant());
  const auto start = std::chrono::steady_clock::now();
  engine::SweepSpec spec = table1_spec(ctx, opt, scenarios, seeds);
  std::vector<Approach> approaches;
  for (const std::string& letter : spec.approaches) approaches.push_back(parse_approach(letter));
  engine::SweepResults r = engine::run_sweep(
      std::move(spec), shard, opt.threads,
      [&](std::size_t a, std::size_t s, std::uint64_t seed) {
        const RunResult run = simulate(ctx, scenarios[s], seed, run_options(opt, approaches[a]));
        return std::vector<double>{run.cost.total(), run.saturated ? 1.0 : 0.0};
      },
      "table1");
  if (wall_time_s != nullptr) *wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return r;
}

nlohmann::json table1_outputs(const engine::SweepResults& results, const std::string& out_dir, bool plots) {
  const engine::SweepSpec& spec = results.spec;
  const nlohmann::json& cfg = spec.config;
  const std::size_t na = spec.approaches.size();
  const std::size_t ns = spec.scenarios.size();
  const std::size_t seeds = spec.seeds;
  const std::size_t cost = results.metric("cost");
  const engine::SweepSummary sm = engine::summarize_metric(results, cost, 0);
  std::size_t saturated_runs = 0;
  for (std::size_t i = 0; i < spec.runs(); ++i) if (results.at(i, results.metric("saturated")) != 0) ++saturated_runs;

  nlohmann::json j;
  j["plant"] = cfg.at("plant");
  j["number_format"] = cfg.at("number_format");
  j["discretizer"] = cfg.at("discretizer");
  j["noise_model"] = cfg.at("noise_model");
  j["seed"] = spec.first_seed;
  j["experiment"] = "table1";
  j["scenarios"] = ns;
  j["seeds"] = seeds;
  double simulated = 0;
  for (const auto& s : cfg.at("scenarios")) simulated += s.at("duration_s").get<double>();
  j["runs"] = spec.runs();
  j["simulated_seconds"] = simulated * static_cast<double>(na * seeds);
  j["saturated_runs"] = saturated_runs;
  std::ostringstream md;
  // Costs grow with the set-point amplitude squared, so the mean cost is dominated by the
  // large-amplitude scenarios; the scenario-weighted ratio gives every scenario one vote:
  // per seed, the mean over scenarios of cost/cost_A.
  md << "| approach | description | mean cost J | 95 % CI | ratio to A | ratio 95 % CI | scenario-weighted ratio |\n"
        "|---|---|---|---|---|---|---|\n";
  std::vector<std::vector<double>> csv_rows;
  for (std::size_t a = 0; a < na; ++a) {
    const util::Summary& c = sm.value[a];
    const util::Summary& r = sm.ratio[a];
    const util::Summary& w = sm.ratio_weighted[a];
    const std::string& letter = spec.approaches[a];
    const char* description = info(parse_approach(letter)).description;
    j["approaches"][letter] = {{"description", description},
                               {"available", true},
                               {"cost_mean", c.mean},
                               {"cost_ci95", c.ci95},
                               {"ratio_to_A", sm.ratio_of_means[a]},
                               {"ratio_mean", r.mean},
                               {"ratio_ci95", r.ci95},
                               {"ratio_scenario_weighted", w.mean},
                               {"ratio_scenario_weighted_ci95", w.ci95}};
    char line[320];
    std::snprintf(line, sizeof line, "| %s | %s | %.5f | ± %.5f | %.4f | ± %.4f | %.4f ± %.4f |\n", letter.c_str(),
                  description, c.mean, c.ci95, sm.ratio_of_means[a], r.ci95, w.mean, w.ci95);
    md << line;
    csv_rows.push_back({static_cast<double>(a), c.mean, c.ci95, r.mean, r.ci95});
  }
  if (cfg.contains("unavailable_approaches")) {
    for (const auto& [letter, why] : cfg.at("unavailable_approaches").items()) {
      const char* description = info(parse_approach(letter)).description;
      j["approaches"][letter] = {{"description", description}, {"available", false}, {"unavailable_reason", why}};
      md << "| " << letter << " | " << description << " | unavailable: " << why.get<std::string>() << " | | | | |\n";
    }
  }
  // Paired differences of the per-seed mean cost (every approach sees the same draws).
  if (!sm.paired.empty()) j["paired_differences"] = engine::paired_differences_json(results, sm);
  // Per-scenario table: mean cost and ratio to A.
  std::ostringstream per;
  per << "| scenario | jitter | amplitude (V) | change period (s) | " << spec.approaches[0];
  for (std::size_t a = 1; a < na; ++a) per << " | " << spec.approaches[a] << "/" << spec.approaches[0];
  per << " |\n|---|---|---|---|";
  for (std::size_t a = 0; a < na; ++a) per << "---|";
  per << "\n";
  nlohmann::json js = nlohmann::json::array();
  for (std::size_t s = 0; s < ns; ++s) {
    const nlohmann::json& sc = cfg.at("scenarios").at(s);
    std::vector<double> mean(na);
    for (std::size_t a = 0; a < na; ++a) mean[a] = sm.per_scenario[a][s].mean;
    const std::string jitter = sc.at("jitter").get<std::string>();
    const double amplitude = sc.at("amplitude_volts").get<double>();
    const double change = sc.at("change_period_s").get<double>();
    char line[320];
    std::snprintf(line, sizeof line, "| %s | %s | %.2f | %.2f | %.5f |", spec.scenarios[s].c_str(), jitter.c_str(),
                  amplitude, change, mean[0]);
    per << line;
    for (std::size_t a = 1; a < na; ++a) {
      std::snprintf(line, sizeof line, " %.4f |", mean[a] / mean[0]);
      per << line;
    }
    per << "\n";
    nlohmann::json e = {{"name", spec.scenarios[s]}, {"jitter", jitter}, {"amplitude_volts", amplitude},
                        {"change_period_s", change}, {"duration_s", sc.at("duration_s")}};
    for (std::size_t a = 0; a < na; ++a) e["cost_mean"][spec.approaches[a]] = mean[a];
    js.push_back(e);
  }
  j["per_scenario"] = js;
  j["markdown"] = md.str();
  j["markdown_per_scenario"] = per.str();
  {
    std::ostringstream out;
    out << "Table I: mean cost over " << ns << " scenarios, " << seeds << " seeds each ("
        << cfg.at("number_format").get<std::string>() << ", " << cfg.at("discretizer").get<std::string>() << ")\n\n"
        << md.str() << "\nPer scenario (mean over seeds):\n\n" << per.str();
    util::write_text(path_in(out_dir, "table1.md"), out.str());  // atomic and checked; creates the folder
  }
  std::vector<std::vector<double>> raw;
  for (std::size_t a = 0; a < na; ++a)
    for (std::size_t s = 0; s < ns; ++s)
      for (std::size_t k = 0; k < seeds; ++k)
        raw.push_back({static_cast<double>(a), static_cast<double>(s), static_cast<double>(spec.first_seed + k),
                       results.at(a, s, k, cost)});
  util::write_csv(path_in(out_dir, "table1_runs.csv"), {"approach_index", "scenario_index", "seed", "cost"}, raw);
  util::write_csv(path_in(out_dir, "table1.csv"), {"approach_index", "cost_mean", "cost_ci95", "ratio_mean", "ratio_ci95"}, csv_rows);
  if (plots) {
    std::ostringstream xtics;
    for (std::size_t a = 0; a < na; ++a) xtics << (a == 0 ? "" : ", ") << util::gnuplot_quote(spec.approaches[a]) << " " << a;
    std::ostringstream g;
    g << util::gnuplot_png_terminal(1100, 700) << "set output 'table1.png'\nset datafile separator ','\nset grid ytics\nset style fill solid 0.6\n"
      << "set boxwidth 0.6\nset xtics (" << xtics.str() << ")\nset xrange [-0.6:" << na - 1 << ".6]\nset yrange [0:*]\n"
      << "set title 'Table I: mean control cost over " << ns << " scenarios x " << seeds << " seeds (95 % CI)'\n"
      << "set ylabel 'cost J'\nset key off\n"
      << "plot 'table1.csv' using 1:2 skip 1 with boxes lc rgb '#4c72b0', '' using 1:2:3 skip 1 with yerrorbars pt 0 lw 2 lc rgb 'black'\n";
    util::run_gnuplot(out_dir, "table1.gp", g.str());
  }
  j["files"] = {"table1.md", "table1.csv", "table1_runs.csv", "table1.png"};
  return j;
}

}  // namespace oneshot::sim

namespace oneshot::sim {

nlohmann::json run_table1(const SimContext& ctx, const CommonOptions& opt, const std::vector<Scenario>& scenarios,
                          std::size_t seeds, const engine::Shard& shard, double* wall_time_s) {
  // No folder before the first file: a run refused by its checks leaves nothing behind.
  const engine::SweepResults r = table1_sweep(ctx, opt, scenarios, seeds, shard, wall_time_s);
  if (!shard.whole()) {
    const nlohmann::json j = engine::shard_to_json(r);
    util::write_json(path_in(opt.out_dir, engine::shard_file_name("table1", shard)), j);
    return j;
  }
  return table1_outputs(r, opt.out_dir, opt.plots);
}

}  // namespace oneshot::sim
