/// @file ncs_table.cpp
/// @brief E4: every approach on the ten scenarios, the same draws for every approach
///        (common random numbers), summarized by the engine's sweep statistics.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <map>
#include <sstream>
#include <stdexcept>

#include "ncs_analytic.hpp"
#include "ncs_experiments.hpp"
#include "ncs_cache_pools.hpp"
#include "ncs_loop.hpp"
#include "oneshot/engine/sweep_statistics.hpp"
#include "oneshot/util/output_files.hpp"

namespace oneshot::ncs {
namespace {

using util::path_in;

Scenario scenario_from(const nlohmann::json& j) {
  Scenario s;
  s.name = j.at("name").get<std::string>();
  s.amplitude_volts = j.at("amplitude_volts").get<double>();
  s.period_s = j.at("period_s").get<double>();
  s.max_delay_ms = j.at("max_delay_ms").get<double>();
  s.noise_scale = j.at("noise_scale").get<double>();
  s.duration_s = j.at("duration_s").get<double>();
  return s;
}

}  // namespace

engine::SweepResults table_sweep(const Context& ctx, const TableOptions& opt, const engine::Shard& shard) {
  if (opt.seeds < 2) throw std::invalid_argument("ncs table needs at least 2 seeds for confidence intervals");
  if (opt.approaches.empty() || opt.approaches.front() != Approach::kI) {
    throw std::invalid_argument("ncs table: the approaches must start with I (the reference of every ratio)");
  }
  std::vector<Scenario> scenarios = opt.scenarios;
  if (scenarios.empty()) {
    scenarios = default_scenarios();
    for (Scenario& s : scenarios) s.duration_s = opt.duration_s;
  }
  engine::SweepSpec spec;
  spec.study = "ncs";
  spec.experiment = "table";
  for (Approach a : opt.approaches) spec.approaches.emplace_back(name(a));
  nlohmann::json sc = nlohmann::json::array();
  for (const Scenario& s : scenarios) {
    spec.scenarios.push_back(s.name);
    sc.push_back({{"name", s.name}, {"amplitude_volts", s.amplitude_volts}, {"period_s", s.period_s},
                  {"max_delay_ms", s.max_delay_ms}, {"noise_scale", s.noise_scale}, {"duration_s", s.duration_s},
                  {"s_plus_mean_tau_io_us", ctx.mean_tau_io_us(s)}, {"late_sampling_D_us", ctx.worst_chain_us(s)}});
  }
  spec.first_seed = opt.first_seed;
  spec.seeds = opt.seeds;
  spec.metrics = {"cost", "late", "saturated", "faults"};
  spec.config = {{"plant", ctx.plant().name},
                 {"plant_source", ctx.plant().source},
                 {"noise_free", opt.noise_free},
                 {"leg_delay_min_us", ctx.timing().leg_min_us},
                 {"compute_us", {ctx.timing().compute_min_us, ctx.timing().compute_max_us}},
                 {"scenarios", sc}};
  if (!opt.faults.empty()) {  // only then: the clean table's spec (and its shards) stay as they were
    engine::check_fault_targets(opt.faults, {"as", "sc", "ca"}, node_names());
    spec.config["inject"] = opt.faults.text;
  }
  if (opt.analytic) {  // only then: the table's spec stays as it was without
    spec.config["analytic"] = true;
    spec.metrics.insert(spec.metrics.end(), std::begin(kAnalyticMetrics), std::end(kAnalyticMetrics));
  }
  const std::vector<Approach> approaches = opt.approaches;
  ShapeCachePools pool;  // the sweep's: per thread, bounded (plant_cache_pool.hpp)
  RunOptions ro;
  ro.noise_free = opt.noise_free;
  ro.faults = opt.faults;
  ro.caches = &pool;
  const bool analytic = opt.analytic;
  return engine::run_sweep(
      spec, shard, opt.threads,
      [&](std::size_t a, std::size_t s, std::uint64_t seed) {
        const RunResult r = run(ctx, approaches[a], scenarios[s], seed, ro);
        std::vector<double> v{r.cost, static_cast<double>(r.late), static_cast<double>(r.saturated),
                              static_cast<double>(r.faults)};
        if (analytic) {
          const auto x = analytic_metrics(ctx, approaches[a], scenarios[s], seed, ro);
          v.insert(v.end(), x.begin(), x.end());
        }
        return v;
      },
      opt.noise_free ? "ncs table (noise-free)" : "ncs table");
}

nlohmann::json table_outputs(const engine::SweepResults& results, const std::string& out_dir, bool plots) {
  util::make_directory(out_dir);
  const engine::SweepSpec& spec = results.spec;
  const std::size_t na = spec.approaches.size();
  const std::size_t ns = spec.scenarios.size();
  const std::size_t seeds = spec.seeds;
  const std::size_t cost = results.metric("cost");
  const engine::SweepSummary sm = engine::summarize_metric(results, cost, 0);
  const bool noise_free = spec.config.at("noise_free").get<bool>();
  std::vector<Scenario> scenarios;
  for (const auto& s : spec.config.at("scenarios")) scenarios.push_back(scenario_from(s));

  nlohmann::json j;
  j["study"] = "ncs";
  j["experiment"] = noise_free ? "table --noise-free" : "table";
  j["plant"] = spec.config.at("plant");
  j["noise_free"] = noise_free;
  j["first_seed"] = spec.first_seed;
  j["seeds"] = seeds;
  j["scenarios"] = spec.config.at("scenarios");
  j["runs"] = spec.runs();
  if (spec.config.contains("inject")) j["inject"] = spec.config.at("inject");
  std::ostringstream md;
  // The ratios' reference is the first approach: I, or IK for a plant whose state I cannot send (n > 6).
  const std::string reference = spec.approaches.empty() ? std::string("I") : spec.approaches[0];
  md << "| approach | description | mean cost J | 95 % CI | ratio to " << reference
     << " (95 % CI) | scenario-weighted ratio (95 % CI) | late | saturated |\n"
        "|---|---|---|---|---|---|---|---|\n";
  for (std::size_t a = 0; a < na; ++a) {
    double late = 0;
    double sat = 0;
    double faults = 0;
    for (std::size_t s = 0; s < ns; ++s) {
      for (std::size_t k = 0; k < seeds; ++k) {
        late += results.at(a, s, k, results.metric("late"));
        sat += results.at(a, s, k, results.metric("saturated"));
        faults += results.at(a, s, k, results.metric("faults"));
      }
    }
    const std::string& nm = spec.approaches[a];
    const Approach ap = parse_any_approach(nm);
    j["approaches"][nm] = {{"description", description(ap)},
                           {"cost_mean", sm.value[a].mean},
                           {"cost_ci95", sm.value[a].ci95},
                           {"ratio_to_" + reference, sm.ratio_of_means[a]},
                           {"ratio_mean", sm.ratio[a].mean},
                           {"ratio_ci95", sm.ratio[a].ci95},
                           {"ratio_scenario_weighted", sm.ratio_weighted[a].mean},
                           {"ratio_scenario_weighted_ci95", sm.ratio_weighted[a].ci95},
                           {"late_commands", late},
                           {"saturated_commands", sat},
                           {"estimator_faults", faults}};
    char line[400];
    std::snprintf(line, sizeof line, "| %s | %s | %.6f | ± %.6f | %.4f ± %.4f | %.4f ± %.4f | %.0f | %.0f |\n", nm.c_str(),
                  description(ap), sm.value[a].mean, sm.value[a].ci95, sm.ratio_of_means[a], sm.ratio[a].ci95,
                  sm.ratio_weighted[a].mean, sm.ratio_weighted[a].ci95, late, sat);
    md << line;
  }
  engine::add_order_by_mean(j, results, sm);
  const std::string order_text = j.at("order_text").get<std::string>();
  if (!sm.paired.empty()) j["paired_differences"] = engine::paired_differences_json(results, sm);
  // Per scenario: mean cost of the reference (the first approach: I, or IK where I cannot run) and ratios to it.
  std::ostringstream per;
  const std::string& ref = spec.approaches[0];
  per << "| scenario | " << ref;
  for (std::size_t a = 1; a < na; ++a) per << " | " << spec.approaches[a] << "/" << ref;
  per << " |\n|---|";
  for (std::size_t a = 0; a < na; ++a) per << "---|";
  per << "\n";
  for (std::size_t s = 0; s < ns; ++s) {
    nlohmann::json e = {{"name", spec.scenarios[s]}};
    char line[64];
    std::snprintf(line, sizeof line, "| %s | %.5f |", spec.scenarios[s].c_str(), sm.per_scenario[0][s].mean);
    per << line;
    for (std::size_t a = 0; a < na; ++a) {
      e["cost_mean"][spec.approaches[a]] = sm.per_scenario[a][s].mean;
      e["cost_ci95"][spec.approaches[a]] = sm.per_scenario[a][s].ci95;
      e["ratio_to_" + reference][spec.approaches[a]] = sm.per_scenario_ratio[a][s].mean;
      e["ratio_to_" + reference + "_ci95"][spec.approaches[a]] = sm.per_scenario_ratio[a][s].ci95;
      if (a > 0) {
        std::snprintf(line, sizeof line, " %.4f |", sm.per_scenario_ratio[a][s].mean);
        per << line;
      }
    }
    per << "\n";
    j["per_scenario"].push_back(e);
  }
  // Noise-free invariants: A = I run by run; S against the delay level d.
  const auto index_of = [&](const char* nm) -> std::ptrdiff_t {
    const auto it = std::find(spec.approaches.begin(), spec.approaches.end(), nm);
    return it == spec.approaches.end() ? -1 : it - spec.approaches.begin();
  };
  const std::ptrdiff_t ia = index_of("A");
  const std::ptrdiff_t is = index_of("S");
  if (ia > 0) {
    double worst = 0;
    for (std::size_t s = 0; s < ns; ++s)
      for (std::size_t k = 0; k < seeds; ++k)
        worst = std::fmax(worst, std::fabs(results.at(static_cast<std::size_t>(ia), s, k, cost) / results.at(0, s, k, cost) - 1));
    j["A_vs_I_max_abs_ratio_minus_1"] = worst;
  }
  if (is > 0) {
    std::map<double, std::pair<double, int>> by_d;
    for (std::size_t s = 0; s < ns; ++s) {
      auto& acc = by_d[scenarios[s].max_delay_ms];
      acc.first += sm.per_scenario_ratio[static_cast<std::size_t>(is)][s].mean;
      acc.second += 1;
    }
    double prev = 0;
    bool increasing = true;
    for (const auto& [d, acc] : by_d) {
      const double r = acc.first / acc.second;
      char key[32];
      std::snprintf(key, sizeof key, "%g", d);
      j["S_ratio_to_I_by_delay_ms"][key] = r;
      increasing = increasing && r > prev;
      prev = r;
    }
    j["S_ratio_increases_with_delay"] = increasing;
  }
  if (spec.config.contains("analytic")) analytic_outputs(results, sm, j, md);
  j["markdown"] = md.str();
  j["markdown_per_scenario"] = per.str();
  {
    std::ofstream out(path_in(out_dir, "table.md"));
    out << "Study ncs, " << (noise_free ? "noise-free, " : "") << ns << " scenarios x " << seeds << " seeds\n\n"
        << md.str() << "\nOrder by mean cost: " << order_text << "\n\nPer scenario (mean over seeds):\n\n" << per.str();
  }
  engine::write_summary_files(results, sm, out_dir, "table", plots);
  j["files"] = {"table.md", "table_runs.csv", "table_summary.csv", "table.png"};
  return j;
}

std::string paired_differences_markdown(const nlohmann::json& table, const std::vector<std::string>& pairs) {
  std::ostringstream md;
  md << "Paired differences of the mean cost (per seed, 95 % CI):\n\n| pair | mean | 95 % CI |\n|---|---|---|\n";
  const nlohmann::json& p = table.at("paired_differences");
  for (const std::string& key : pairs) {
    if (!p.contains(key)) continue;
    char line[160];
    const auto value = [](const nlohmann::json& v) { return v.is_null() ? std::nan("") : v.get<double>(); };  // null: not finite
    std::snprintf(line, sizeof line, " | %.6f | ± %.6f |\n", value(p.at(key).at("mean")), value(p.at(key).at("ci95")));
    md << "| " << key << line;
  }
  return md.str();
}

std::string table_section_markdown(const nlohmann::json& table, const std::vector<std::string>& pairs,
                                   const std::string& plot_path) {
  std::ostringstream md;
  md << table.at("markdown").get<std::string>() << "\nOrder by mean cost (measured): " << table.at("order_text").get<std::string>()
     << "\n\n" << paired_differences_markdown(table, pairs) << "\n";
  if (!plot_path.empty()) md << "![mean cost per approach, 95 % intervals](" << plot_path << ")\n\n";
  return md.str();
}

}  // namespace oneshot::ncs
