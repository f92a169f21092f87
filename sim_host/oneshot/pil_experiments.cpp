/// @file pil_experiments.cpp
/// @brief Processor-in-the-loop runs: one scenario and Table I with the job in the emulated MCU
///        (MCU instruction counts: pil_exectime.cpp).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <iostream>
#include <sstream>

#include "c_job_host.hpp"
#include "oneshot_experiments.hpp"
#include "pil_job_frames.hpp"
#include "oneshot/util/output_files.hpp"
#include "oneshot/sim/pil_link.hpp"
#include "oneshot/util/progress_bar.hpp"
#include "oneshot/util/statistics.hpp"

namespace oneshot::sim {

namespace {

/// Host run options that record every job, for the comparison with the MCU.
RunOptions options_for(const CommonOptions& opt, Approach a) {
  RunOptions r = run_options(opt, a);
  r.record_jobs = true;
  return r;
}

PilOptions matching(const PilOptions& base, const CommonOptions& opt) {
  if (opt.format == NumberFormat::kQ15) {
    throw std::invalid_argument("the q15 C job runs in the fixed-point table images as approach 6: see `exectime "
                                "--noise-model exact` (c99_half_*_q15)");
  }
  if (opt.format == NumberFormat::kFloatPoly) {
    throw std::invalid_argument("the float_poly C job runs in the float table images as approach 6: see `exectime "
                                "--noise-model exact` (c99_half_table_float_poly)");
  }
  PilOptions p = base;
  p.format = to_string(opt.format);
  p.discretizer = to_string(opt.discretizer);
  if (opt.format == NumberFormat::kDouble) {
    throw std::invalid_argument("the firmware runs float or fixed (--number-format float|fixed), not double");
  }
  return p;
}

struct Comparison {
  std::size_t jobs = 0;
  std::size_t identical_codes = 0;     // applied input identical
  std::size_t identical_estimates = 0; // every estimate entry identical
  double max_estimate_diff = 0;
};

Comparison compare(const RunResult& host, const RunResult& mcu) {
  Comparison c;
  c.jobs = std::min(host.job_records.size(), mcu.job_records.size());
  for (std::size_t k = 0; k < c.jobs; ++k) {
    const JobRecord& a = host.job_records[k];
    const JobRecord& b = mcu.job_records[k];
    if (a.u_volts == b.u_volts) ++c.identical_codes;
    bool same = true;
    for (std::size_t i = 0; i < a.estimate.size(); ++i) {
      same = same && a.estimate[i] == b.estimate[i];
      c.max_estimate_diff = std::max(c.max_estimate_diff, std::fabs(a.estimate[i] - b.estimate[i]));
    }
    if (same) ++c.identical_estimates;
  }
  return c;
}

}  // namespace

nlohmann::json run_pil_compare(const SimContext& ctx, const CommonOptions& opt, const PilOptions& base,
                               const Scenario& scenario, Approach approach) {
  const PilOptions p = matching(base, opt);
  PilLink link(p);
  RunOptions host_opt = options_for(opt, approach);
  RunOptions mcu_opt = host_opt;
  mcu_opt.pil = &link;
  const auto t0 = std::chrono::steady_clock::now();
  const RunResult mcu = simulate(ctx, scenario, opt.seed, mcu_opt);
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const RunResult host = simulate(ctx, scenario, opt.seed, host_opt);
  const Comparison c = compare(host, mcu);
  nlohmann::json j;
  j["experiment"] = "pil";
  j["target"] = link.info().target;
  j["image"] = link.image();
  j["number_format"] = link.info().format;
  j["discretizer"] = link.info().discretizer;
  j["approach"] = std::string(1, info(approach).letter);
  j["scenario"] = scenario.name;
  j["seed"] = opt.seed;
  j["jobs"] = c.jobs;
  j["host_cost"] = host.cost.total();
  j["pil_cost"] = mcu.cost.total();
  j["cost_relative_difference"] = std::fabs(mcu.cost.total() - host.cost.total()) / host.cost.total();
  j["identical_inputs"] = c.identical_codes;
  j["identical_estimates"] = c.identical_estimates;
  j["max_estimate_difference"] = c.max_estimate_diff;
  j["bit_identical"] = c.identical_codes == c.jobs && c.identical_estimates == c.jobs;
  j["resends"] = link.resends();
  j["pil_wall_time_s"] = wall;
  j["overruns"] = mcu.overruns;
  j["stack_peak_bytes"] = link.stack_peak_bytes();
  return j;
}

nlohmann::json run_pil_table1(const SimContext& ctx, const CommonOptions& opt, const PilOptions& base,
                              const std::vector<Scenario>& scenarios, std::size_t seeds) {
  const PilOptions p = matching(base, opt);
  PilLink link(p);
  const std::size_t na = kAllApproaches.size();
  std::vector<std::vector<double>> per_seed_host(na, std::vector<double>(seeds, 0));
  std::vector<std::vector<double>> per_seed_mcu(na, std::vector<double>(seeds, 0));
  std::size_t jobs = 0;
  std::size_t identical = 0;
  const auto t0 = std::chrono::steady_clock::now();
  {
    util::ProgressBar bar("pil table1", scenarios.size() * seeds * na);
    for (std::size_t s = 0; s < scenarios.size(); ++s)
      for (std::size_t k = 0; k < seeds; ++k)
        for (std::size_t a = 0; a < na; ++a) {
          RunOptions host_opt = options_for(opt, kAllApproaches[a]);
          RunOptions mcu_opt = host_opt;
          mcu_opt.pil = &link;
          const RunResult mcu = simulate(ctx, scenarios[s], opt.seed + k, mcu_opt);
          const RunResult host = simulate(ctx, scenarios[s], opt.seed + k, host_opt);
          const Comparison c = compare(host, mcu);
          jobs += c.jobs;
          identical += std::min(c.identical_codes, c.identical_estimates);
          per_seed_host[a][k] += host.cost.total() / static_cast<double>(scenarios.size());
          per_seed_mcu[a][k] += mcu.cost.total() / static_cast<double>(scenarios.size());
          bar.tick();
        }
  }
  nlohmann::json j;
  j["experiment"] = "pil_table1";
  j["target"] = link.info().target;
  j["number_format"] = link.info().format;
  j["discretizer"] = link.info().discretizer;
  j["scenarios"] = scenarios.size();
  j["seeds"] = seeds;
  j["jobs"] = jobs;
  j["bit_identical_jobs"] = identical;
  j["resends"] = link.resends();
  j["wall_time_s"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const util::Summary a_host = util::summarize(per_seed_host[0]);
  const util::Summary a_mcu = util::summarize(per_seed_mcu[0]);
  std::ostringstream md;
  md << "| approach | host mean cost | 95 % CI | MCU mean cost | 95 % CI | MCU ratio to A |\n|---|---|---|---|---|---|\n";
  for (std::size_t a = 0; a < na; ++a) {
    const util::Summary h = util::summarize(per_seed_host[a]);
    const util::Summary m = util::summarize(per_seed_mcu[a]);
    const std::string letter(1, info(kAllApproaches[a]).letter);
    j["approaches"][letter] = {{"host_cost_mean", h.mean}, {"host_cost_ci95", h.ci95}, {"cost_mean", m.mean},
                               {"cost_ci95", m.ci95}, {"ratio_to_A", m.mean / a_mcu.mean},
                               {"host_ratio_to_A", h.mean / a_host.mean}};
    char line[200];
    std::snprintf(line, sizeof line, "| %s | %.5f | ± %.5f | %.5f | ± %.5f | %.4f |\n", letter.c_str(), h.mean, h.ci95,
                  m.mean, m.ci95, m.mean / a_mcu.mean);
    md << line;
  }
  j["markdown"] = md.str();
  return j;
}

}  // namespace oneshot::sim
