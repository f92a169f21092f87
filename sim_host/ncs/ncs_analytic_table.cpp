/// @file ncs_analytic_table.cpp
/// @brief `ncs table --analytic`: the analytic mean and interval over the timing draws beside
///        the Monte Carlo ones, the paired difference, and the variance reduction.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

#include "ncs_analytic.hpp"
#include "oneshot/util/statistics.hpp"

namespace oneshot::ncs {

void analytic_outputs(const engine::SweepResults& results, const engine::SweepSummary& mc, nlohmann::json& j,
                      std::ostringstream& md) {
  const engine::SweepSpec& spec = results.spec;
  const std::size_t ia = results.metric("analytic");
  const std::size_t ir = results.metric("analytic_refused");
  const std::size_t im = results.metric("analytic_mismatch");
  const engine::SweepSummary an = engine::summarize_metric(results, ia, 0);
  md << "\nAnalytic: E[J] over the process and measurement noise, exact for each timing draw (the Monte Carlo "
        "is over the delays only); MC − analytic paired per seed; variance reduction = (MC CI / analytic CI)², "
        "the Monte Carlo runs needed for the analytic interval width per timing draw.\n\n"
        "| approach | analytic mean | 95 % CI | analytic ratio to I (95 % CI) | MC − analytic | variance reduction |\n"
        "|---|---|---|---|---|---|\n";
  double table_vr = std::numeric_limits<double>::infinity();
  std::vector<double> vrs;
  // Runs refused per approach: their analytic column is 0, so no figure is taken from them
  // (the approach is reported refused with the reason, its pairs and ratios left out).
  std::vector<std::size_t> refused_runs(spec.approaches.size(), 0);
  std::vector<int> first_code(spec.approaches.size(), 0);
  for (std::size_t a = 0; a < spec.approaches.size(); ++a)
    for (std::size_t s = 0; s < spec.scenarios.size(); ++s)
      for (std::size_t k = 0; k < spec.seeds; ++k) {
        const int c = static_cast<int>(results.at(a, s, k, ir));
        if (c == 0) continue;
        ++refused_runs[a];
        if (first_code[a] == 0) first_code[a] = c;
      }
  const bool reference_refused = refused_runs[0] > 0;
  for (std::size_t a = 0; a < spec.approaches.size(); ++a) {
    const std::string& nm = spec.approaches[a];
    nlohmann::json& ja = j["approaches"][nm];
    const std::size_t refused = refused_runs[a];
    const int code = first_code[a];
    double mismatch = 0;
    for (std::size_t s = 0; s < spec.scenarios.size(); ++s)
      for (std::size_t k = 0; k < spec.seeds; ++k) mismatch = std::fmax(mismatch, results.at(a, s, k, im));
    char line[400];
    if (refused > 0) {
      ja["analytic_refused"] = analytic_refusal_text(code);
      ja["analytic_refused_runs"] = refused;
      md << "| " << nm << " | refused (" << refused << " runs): " << analytic_refusal_text(code) << " | | | | |\n";
      continue;
    }
    std::vector<double> diff;
    for (std::size_t k = 0; k < spec.seeds; ++k) diff.push_back(mc.per_seed[a][k] - an.per_seed[a][k]);
    const util::Summary d = util::summarize(diff);
    const double ci_an = an.value[a].ci95;
    // An interval at the rounding level of the mean: the timing does not move the expected
    // cost (I, IK: no delays; AKl: τ = D fixed), no Monte Carlo width can be compared.
    const bool spread = ci_an > 1e-12 * std::fabs(an.value[a].mean);
    const double vr = spread ? std::pow(mc.value[a].ci95 / ci_an, 2) : std::numeric_limits<double>::quiet_NaN();
    if (std::isfinite(vr)) vrs.push_back(vr);
    ja["analytic_mean"] = an.value[a].mean;
    ja["analytic_ci95"] = ci_an;
    if (reference_refused) {  // a ratio to a refused I would divide by its zeros (as table1 --analytic)
      ja["analytic_ratio_to_I"] = "reference I refused";
    } else {
      ja["analytic_ratio_to_I"] = an.ratio[a].mean;
      ja["analytic_ratio_to_I_ci95"] = an.ratio[a].ci95;
    }
    ja["mc_minus_analytic_mean"] = d.mean;
    ja["mc_minus_analytic_ci95"] = d.ci95;
    ja["analytic_max_mean_mismatch"] = mismatch;
    if (std::isfinite(vr)) {
      ja["variance_reduction"] = vr;
      table_vr = std::fmin(table_vr, vr);
    } else {
      ja["variance_reduction"] = nullptr;
      ja["variance_reduction_note"] = "the expected cost does not depend on the timing draws (interval at rounding level)";
    }
    char ratio[64] = "— (I refused)";
    if (!reference_refused) std::snprintf(ratio, sizeof ratio, "%.5f ± %.5f", an.ratio[a].mean, an.ratio[a].ci95);
    std::snprintf(line, sizeof line, "| %s | %.6f | ± %.6f | %s | %.6f ± %.6f | %s |\n", nm.c_str(), an.value[a].mean,
                  ci_an, ratio, d.mean, d.ci95, std::isfinite(vr) ? std::to_string(vr).c_str() : "∞ (no timing spread)");
    md << line;
  }
  for (const auto& p : an.paired) {
    if (refused_runs[p.a] > 0 || refused_runs[p.b] > 0) continue;
    j["analytic_paired_differences"][spec.approaches[p.a] + "-" + spec.approaches[p.b]] = {{"mean", p.diff.mean},
                                                                                          {"ci95", p.diff.ci95}};
  }
  // The table's figure: the smallest reduction over the approaches with a spread (and their median).
  if (std::isfinite(table_vr)) {
    j["variance_reduction"] = table_vr;
    std::sort(vrs.begin(), vrs.end());
    const std::size_t n = vrs.size();
    j["variance_reduction_median"] = n % 2 == 1 ? vrs[n / 2] : 0.5 * (vrs[n / 2 - 1] + vrs[n / 2]);
  } else {
    j["variance_reduction"] = nullptr;
  }
}

}  // namespace oneshot::ncs
