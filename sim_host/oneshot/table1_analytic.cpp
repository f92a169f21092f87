/// @file table1_analytic.cpp
/// @brief `table1 --analytic` (see table1_analytic.hpp).
#include "table1_analytic.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iterator>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "linear_board.hpp"
#include "oneshot/engine/sweep_statistics.hpp"
#include "oneshot/util/output_files.hpp"
#include "oneshot/util/statistics.hpp"
#include "table1.hpp"

namespace oneshot::sim {
namespace {

/// Refusal reasons by code (1 …; 0: none).
constexpr const char* kReasons[] = {kLinearRefusalRange, kLinearRefusalInexact, kLinearRefusalMismatch};

double refusal_code(const std::string& reason) {
  if (reason.empty()) return 0;
  for (std::size_t i = 0; i < std::size(kReasons); ++i)
    if (reason == kReasons[i]) return static_cast<double>(i + 1);
  return static_cast<double>(std::size(kReasons) + 1);
}

const char* refusal_text(double code) {
  const auto c = static_cast<std::size_t>(code);
  return c >= 1 && c <= std::size(kReasons) ? kReasons[c - 1] : "unknown";
}

/// Written instead of a ratio to A when A's analytic value is refused.
constexpr const char* kReferenceRefused = "reference A refused";

using util::path_in;

/// Mean and interval of x_k (over seeds) as {"mean", "ci95"}.
nlohmann::json summary(const std::vector<double>& x) {
  const util::Summary s = util::summarize(x);
  return {{"mean", s.mean}, {"ci95", s.ci95}};
}

}  // namespace

const char* decide_within(double mean, double ci95, double tol) {
  if (mean + ci95 < tol) return "yes";
  if (mean - ci95 > tol) return "no";
  return "undecided";
}

engine::SweepResults table1_analytic_sweep(const SimContext& ctx, const CommonOptions& opt,
                                           const std::vector<Scenario>& scenarios, std::size_t seeds,
                                           double* wall_time_s) {
  if (seeds < 2) throw std::invalid_argument("table1 needs at least 2 seeds for confidence intervals");
  if (!ctx.generated()) {
    throw std::invalid_argument("table1 --analytic runs the linear board of the compiled-in plant: run without --plant");
  }
  for (const Scenario& s : scenarios) validate_scenario(s, ctx.plant());
  const auto start = std::chrono::steady_clock::now();
  engine::SweepSpec spec = table1_spec(ctx, opt, scenarios, seeds);
  spec.experiment = "table1_analytic";
  spec.metrics = {"analytic", "analytic_refused", "analytic_mismatch", "cost", "out_of_range", "board_cost"};
  spec.config["linear_board"] = "double, PWM average, ADC unquantized";
  std::vector<Approach> approaches;
  for (const std::string& letter : spec.approaches) approaches.push_back(parse_approach(letter));
  engine::SweepResults r = engine::run_sweep(
      std::move(spec), engine::Shard{}, opt.threads,
      [&](std::size_t a, std::size_t s, std::uint64_t seed) {
        const RunOptions ro = run_options(opt, approaches[a]);
        const LinearRunResult an = run_linear_board(ctx, scenarios[s], seed, ro, LinearOptions{true, true});
        const LinearRunResult mc = run_linear_board(ctx, scenarios[s], seed, ro, LinearOptions{true, false});
        const RunResult board = simulate(ctx, scenarios[s], seed, ro);
        return std::vector<double>{an.analytic.total(),          refusal_code(an.refusal), an.mismatch, mc.cost,
                                   static_cast<double>(mc.out_of_range), board.cost.total()};
      },
      "table1 --analytic");
  if (wall_time_s != nullptr) *wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return r;
}

nlohmann::json table1_analytic_outputs(const engine::SweepResults& results, const std::string& out_dir) {
  const engine::SweepSpec& spec = results.spec;
  const std::size_t na = spec.approaches.size();
  const std::size_t ns = spec.scenarios.size();
  const std::size_t seeds = spec.seeds;
  const std::size_t ian = results.metric("analytic");
  const std::size_t iref = results.metric("analytic_refused");
  const std::size_t imis = results.metric("analytic_mismatch");
  const std::size_t imc = results.metric("cost");
  const std::size_t iout = results.metric("out_of_range");
  const std::size_t iboard = results.metric("board_cost");
  const engine::SweepSummary an = engine::summarize_metric(results, ian, 0);
  const engine::SweepSummary mc = engine::summarize_metric(results, imc, 0);
  const engine::SweepSummary bd = engine::summarize_metric(results, iboard, 0);

  nlohmann::json j;
  j["plant"] = spec.config.at("plant");
  j["experiment"] = "table1_analytic";
  j["linear_board"] = spec.config.at("linear_board");
  j["board_number_format"] = spec.config.at("number_format");
  j["seed"] = spec.first_seed;
  j["scenarios"] = ns;
  j["seeds"] = seeds;
  j["runs"] = spec.runs();
  std::ostringstream md;
  md << "Linear board (PWM average, ADC unquantized, double): analytic E[J] over the noise per timing draw beside the "
        "Monte Carlo of the same model; the emulated board's Table I cost beside (quantization cost = board − linear, "
        "paired). Variance reduction = (MC CI / analytic CI)² of the cost and, in brackets, of the ratio to A (paired per "
        "seed: the set-point draws cancel there, the noise does not). Cost-weighted ratio: per seed, the ratio of the "
        "scenario-summed costs (the scenarios with large costs dominate).\n\n"
        "| approach | analytic mean | 95 % CI | linear MC mean | 95 % CI | board mean | quantization cost | "
        "analytic ratio to A, cost-weighted | MC ratio to A, cost-weighted | variance reduction |\n"
        "|---|---|---|---|---|---|---|---|---|---|\n";
  double table_vr = std::numeric_limits<double>::infinity();
  double table_rvr = std::numeric_limits<double>::infinity();
  std::vector<double> vrs;
  std::vector<std::size_t> refused(na, 0);
  for (std::size_t a = 0; a < na; ++a) {
    const std::string& nm = spec.approaches[a];
    nlohmann::json& ja = j["approaches"][nm];
    double code = 0;
    double mismatch = 0;
    double out_of_range = 0;
    for (std::size_t s = 0; s < ns; ++s)
      for (std::size_t k = 0; k < seeds; ++k) {
        const double c = results.at(a, s, k, iref);
        if (c != 0) {
          ++refused[a];
          if (code == 0) code = c;
        }
        mismatch = std::fmax(mismatch, results.at(a, s, k, imis));
        out_of_range += results.at(a, s, k, iout);
      }
    std::vector<double> quant(seeds);
    std::vector<double> diff(seeds);
    for (std::size_t k = 0; k < seeds; ++k) {
      quant[k] = bd.per_seed[a][k] - mc.per_seed[a][k];
      diff[k] = mc.per_seed[a][k] - an.per_seed[a][k];
    }
    ja["cost_mean"] = mc.value[a].mean;
    ja["cost_ci95"] = mc.value[a].ci95;
    ja["cost_ratio_to_A"] = {{"mean", mc.ratio[a].mean}, {"ci95", mc.ratio[a].ci95}};
    ja["mc_jobs_out_of_range"] = out_of_range;
    ja["board_cost_mean"] = bd.value[a].mean;
    ja["board_cost_ci95"] = bd.value[a].ci95;
    ja["quantization_cost"] = summary(quant);
    ja["analytic_max_mean_mismatch"] = mismatch;
    char line[512];
    if (refused[a] > 0) {
      ja["analytic_refused"] = refusal_text(code);
      ja["analytic_refused_runs"] = refused[a];
      std::snprintf(line, sizeof line, "| %s | refused (%zu runs): %s | | %.6f | ± %.6f | %.6f | | | | |\n", nm.c_str(),
                    refused[a], refusal_text(code), mc.value[a].mean, mc.value[a].ci95, bd.value[a].mean);
      md << line;
      continue;
    }
    const double ci_an = an.value[a].ci95;
    const bool spread = ci_an > 1e-12 * std::fabs(an.value[a].mean);
    const double vr = spread ? std::pow(mc.value[a].ci95 / ci_an, 2) : std::numeric_limits<double>::quiet_NaN();
    ja["analytic_mean"] = an.value[a].mean;
    ja["analytic_ci95"] = ci_an;
    ja["mc_minus_analytic"] = summary(diff);
    // Ratios to A (approach 0) only when A's analytic values all hold.
    const bool reference_ok = refused[0] == 0;
    if (reference_ok) {
      ja["analytic_ratio_to_A"] = {{"mean", an.ratio[a].mean}, {"ci95", an.ratio[a].ci95}};
      ja["analytic_ratio_to_A_scenario_weighted"] = {{"mean", an.ratio_weighted[a].mean},
                                                     {"ci95", an.ratio_weighted[a].ci95}};
    } else {
      ja["analytic_ratio_to_A"] = kReferenceRefused;
      ja["analytic_ratio_to_A_scenario_weighted"] = kReferenceRefused;
      ja["ratio_variance_reduction"] = kReferenceRefused;
    }
    // The ratio to A, paired per seed: the set-point draws cancel, the noise remains in the MC.
    const bool ratio_spread = reference_ok && an.ratio[a].ci95 > 0;
    if (ratio_spread) {
      const double rvr = std::pow(mc.ratio[a].ci95 / an.ratio[a].ci95, 2);
      ja["ratio_variance_reduction"] = rvr;
      table_rvr = std::fmin(table_rvr, rvr);
    }
    if (std::isfinite(vr)) {
      ja["variance_reduction"] = vr;
      vrs.push_back(vr);
      table_vr = std::fmin(table_vr, vr);
    } else {
      ja["variance_reduction"] = nullptr;
    }
    const util::Summary q = util::summarize(quant);
    char ratio[96];
    if (reference_ok) {
      std::snprintf(ratio, sizeof ratio, "%.6f ± %.6f", an.ratio[a].mean, an.ratio[a].ci95);
    } else {
      std::snprintf(ratio, sizeof ratio, "%s", kReferenceRefused);
    }
    const std::string rvr_text = ratio_spread ? std::to_string(std::pow(mc.ratio[a].ci95 / an.ratio[a].ci95, 2))
                                              : std::string(reference_ok ? "—" : kReferenceRefused);
    std::snprintf(line, sizeof line, "| %s | %.6f | ± %.6f | %.6f | ± %.6f | %.6f | %.6f ± %.6f | %s | %.5f ± %.5f | %s (%s) |\n",
                  nm.c_str(), an.value[a].mean, ci_an, mc.value[a].mean, mc.value[a].ci95, bd.value[a].mean, q.mean,
                  q.ci95, ratio, mc.ratio[a].mean, mc.ratio[a].ci95,
                  std::isfinite(vr) ? std::to_string(vr).c_str() : "— (no spread)", rvr_text.c_str());
    md << line;
  }
  if (std::isfinite(table_vr)) {
    std::sort(vrs.begin(), vrs.end());
    j["variance_reduction"] = table_vr;
    const std::size_t n = vrs.size();
    j["variance_reduction_median"] = n % 2 == 1 ? vrs[n / 2] : 0.5 * (vrs[n / 2 - 1] + vrs[n / 2]);
  } else {
    j["variance_reduction"] = nullptr;
  }
  // The table's figure for the ratios to A (the smallest over the approaches).
  if (std::isfinite(table_rvr)) j["ratio_variance_reduction"] = table_rvr;

  // Per scenario: B/A (paired per seed) and the 0.2 % decision.
  const auto index_of = [&](const char* letter) {
    return static_cast<std::size_t>(std::find(spec.approaches.begin(), spec.approaches.end(), letter) - spec.approaches.begin());
  };
  const std::size_t ia = index_of("A");
  const std::size_t ib = index_of("B");
  std::ostringstream per;
  nlohmann::json js = nlohmann::json::array();
  if (ia == 0 && ib < na) {  // ratios are to approach 0: A
    per << "\nB/A per scenario (paired per seed; within 0.2 %: yes when the whole interval of B/A − 1 is below 0.2 %, "
           "no when wholly above):\n\n| scenario | analytic B/A | 95 % CI | linear MC B/A | 95 % CI | width MC / "
           "analytic | board B/A | within 0.2 % |\n|---|---|---|---|---|---|---|---|\n";
    for (std::size_t s = 0; s < ns; ++s) {
      bool ok = true;
      for (std::size_t k = 0; k < seeds; ++k)
        ok = ok && results.at(ia, s, k, iref) == 0 && results.at(ib, s, k, iref) == 0;
      const util::Summary& m = mc.per_scenario_ratio[ib][s];
      const util::Summary& b = bd.per_scenario_ratio[ib][s];
      nlohmann::json e = {{"name", spec.scenarios[s]},
                          {"mc_B_over_A", {{"mean", m.mean}, {"ci95", m.ci95}}},
                          {"board_B_over_A", {{"mean", b.mean}, {"ci95", b.ci95}}}};
      char line[512];
      if (!ok) {
        e["within_0_2_percent"] = "refused";
        std::snprintf(line, sizeof line, "| %s | refused | | %.5f | ± %.5f | | %.5f ± %.5f | refused |\n",
                      spec.scenarios[s].c_str(), m.mean, m.ci95, b.mean, b.ci95);
      } else {
        const util::Summary& r = an.per_scenario_ratio[ib][s];
        const char* decision = decide_within(r.mean - 1, r.ci95, kWithinTolerance);
        e["analytic_B_over_A"] = {{"mean", r.mean}, {"ci95", r.ci95}};
        e["within_0_2_percent"] = decision;
        e["width_ratio_mc_over_analytic"] = r.ci95 > 0 ? m.ci95 / r.ci95 : std::numeric_limits<double>::quiet_NaN();
        std::snprintf(line, sizeof line, "| %s | %.6f | ± %.6f | %.5f | ± %.5f | %.1f | %.5f ± %.5f | %s |\n",
                      spec.scenarios[s].c_str(), r.mean, r.ci95, m.mean, m.ci95, r.ci95 > 0 ? m.ci95 / r.ci95 : 0.0,
                      b.mean, b.ci95, decision);
      }
      per << line;
      js.push_back(e);
    }
    if (refused[ia] == 0 && refused[ib] == 0) {
      // Two aggregates over the scenarios, both paired per seed: cost-weighted = the ratio of the
      // scenario-summed costs (the scenarios with large costs dominate), scenario-weighted = the
      // mean over the scenarios of the per-scenario ratio (each scenario counts the same).
      const auto aggregate = [&](const util::Summary& r, const util::Summary& m) {
        return nlohmann::json{{"analytic_mean", r.mean}, {"analytic_ci95", r.ci95}, {"mc_mean", m.mean}, {"mc_ci95", m.ci95},
                              {"within_0_2_percent", decide_within(r.mean - 1, r.ci95, kWithinTolerance)}};
      };
      const nlohmann::json cw = aggregate(an.ratio[ib], mc.ratio[ib]);
      const nlohmann::json sw = aggregate(an.ratio_weighted[ib], mc.ratio_weighted[ib]);
      std::size_t within = 0;
      for (const nlohmann::json& e : js)
        if (e["within_0_2_percent"] == "yes") ++within;
      j["B_over_A"] = {{"cost_weighted", cw}, {"scenario_weighted", sw}, {"scenarios_within", within}, {"scenarios", ns}};
      char line[512];
      std::snprintf(line, sizeof line,
                    "\nB/A over the scenarios (analytic, paired per seed): cost-weighted (ratio of the scenario-summed "
                    "costs) %.6f ± %.6f, within 0.2 %%: %s; scenario-weighted (mean of the per-scenario ratios) "
                    "%.6f ± %.6f, within 0.2 %%: %s; within 0.2 %% in %zu of %zu scenarios.\n",
                    an.ratio[ib].mean, an.ratio[ib].ci95, cw["within_0_2_percent"].get<std::string>().c_str(),
                    an.ratio_weighted[ib].mean, an.ratio_weighted[ib].ci95,
                    sw["within_0_2_percent"].get<std::string>().c_str(), within, ns);
      per << line;
    }
  }
  j["per_scenario"] = js;
  j["markdown"] = md.str() + per.str();
  util::write_text(path_in(out_dir, "table1_analytic.md"),
                   "Table I, analytic (" + std::to_string(ns) + " scenarios, " + std::to_string(seeds) +
                       " timing draws each)\n\n" + md.str() + per.str());
  std::vector<std::vector<double>> raw;
  for (std::size_t a = 0; a < na; ++a)
    for (std::size_t s = 0; s < ns; ++s)
      for (std::size_t k = 0; k < seeds; ++k) {
        std::vector<double> row{static_cast<double>(a), static_cast<double>(s), static_cast<double>(spec.first_seed + k)};
        for (std::size_t m = 0; m < spec.metrics.size(); ++m) row.push_back(results.at(a, s, k, m));
        raw.push_back(row);
      }
  std::vector<std::string> header{"approach_index", "scenario_index", "seed"};
  for (const std::string& m : spec.metrics) header.push_back(m);
  util::write_csv(path_in(out_dir, "table1_analytic_runs.csv"), header, raw);
  j["files"] = {"table1_analytic.md", "table1_analytic_runs.csv"};
  return j;
}

nlohmann::json run_table1_analytic(const SimContext& ctx, const CommonOptions& opt, const std::vector<Scenario>& scenarios,
                                   std::size_t seeds, double* wall_time_s) {
  const engine::SweepResults r = table1_analytic_sweep(ctx, opt, scenarios, seeds, wall_time_s);
  return table1_analytic_outputs(r, opt.out_dir);
}

}  // namespace oneshot::sim
