/// @file ncs_analytic_test.cpp
/// @brief Study ncs, analytic mode (issue 23): noise-free the expected cost is the simulated
///        cost on every approach; with noise the analytic mean lies in the Monte
///        Carlo interval of the same loop; runs that leave the linear regime are refused
///        with the reason; the table's analytic keys.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include "ncs_analytic.hpp"
#include "ncs_experiments.hpp"
#include "ncs_loop.hpp"
#include "ncs_test_support.hpp"
#include "oneshot/util/statistics.hpp"
#include "support/build_flavor.hpp"

namespace oneshot::ncs {
namespace {


TEST(NcsAnalytic, NoiseFreeEqualsTheSimulatedCostOnEveryApproach) {
  RunOptions nf;
  nf.noise_free = true;
  nf.analytic = true;
  double worst = 0;
  double worst_mismatch = 0;
  for (const Approach a : kAllApproaches)
    for (std::uint64_t seed = 1; seed <= 2; ++seed) {
      const RunResult r = run(context(), a, short_scenario(0.5, 14, 1, 3), seed, nf);
      ASSERT_EQ(r.analytic_refusal, "") << name(a);
      EXPECT_EQ(r.analytic.covariance, 0) << name(a);
      EXPECT_EQ(r.analytic.noise_path, 0) << name(a);
      worst = std::fmax(worst, std::fabs(r.analytic.total() / r.cost - 1));
      worst_mismatch = std::fmax(worst_mismatch, r.analytic_mismatch);
      // With noise the mean part is still the noise-free cost the run simulated.
      RunOptions an;
      an.analytic = true;
      const RunResult n = run(context(), a, short_scenario(0.5, 14, 4, 3), seed, an);
      ASSERT_EQ(n.analytic_refusal, "") << name(a);
      worst = std::fmax(worst, std::fabs(n.analytic.mean / n.cost - 1));
      if (a != Approach::kI) {
        EXPECT_GT(n.analytic.covariance + n.analytic.noise_path, 0) << name(a);
      }
    }
  std::printf("noise-free analytic vs simulated: worst relative %.3g, worst mean mismatch %.3g\n", worst, worst_mismatch);
  EXPECT_LT(worst, 1e-13);  // brief: 1e-9
  EXPECT_LT(worst_mismatch, 1e-13);
}

/// The expected cost at a mark is what a run ending there gives (its oracle: that shorter run,
/// same seed), on a period boundary and between events; the mark never changes the run.
TEST(NcsAnalytic, TheCostAtAMarkIsTheCostOfTheRunEndingThere) {
  for (const Approach a : {Approach::kA, Approach::kSK, Approach::kSPlus})
    for (const double mark_s : {1.0, 1.2345}) {
      RunOptions an;
      an.analytic = true;
      const Scenario whole = short_scenario(0.5, 14, 4, 3);
      Scenario until_mark = whole;
      until_mark.duration_s = mark_s;
      const RunResult shorter = run(context(), a, until_mark, 7, an);
      const RunResult plain = run(context(), a, whole, 7, an);
      an.analytic_mark_s = mark_s;
      const RunResult marked = run(context(), a, whole, 7, an);
      ASSERT_EQ(marked.analytic_refusal, "") << name(a);
      EXPECT_GT(marked.analytic_at_mark.covariance, 0) << name(a);
      EXPECT_EQ(marked.analytic_at_mark.mean, shorter.analytic.mean) << name(a) << " at " << mark_s;
      EXPECT_EQ(marked.analytic_at_mark.covariance, shorter.analytic.covariance) << name(a) << " at " << mark_s;
      EXPECT_EQ(marked.analytic_at_mark.noise_path, shorter.analytic.noise_path) << name(a) << " at " << mark_s;
      EXPECT_EQ(marked.analytic.total(), plain.analytic.total()) << name(a);
      EXPECT_EQ(marked.cost, plain.cost) << name(a);
      EXPECT_EQ(plain.analytic_at_mark.total(), 0) << name(a);  // no mark: nothing read
    }
}

TEST(NcsAnalytic, WithNoiseTheAnalyticMeanIsInsideTheMonteCarloInterval) {
  const Scenario sc = short_scenario(0.2, 8, 16, 2);  // noise-dominated
  RunOptions mc;
  RunOptions an;
  an.analytic = true;
  for (const Approach a : {Approach::kS, Approach::kA, Approach::kAK, Approach::kAKl, Approach::kSK, Approach::kSPlus,
                           Approach::kIK}) {
    std::vector<double> cost;
    std::vector<double> analytic;
    std::vector<double> diff;
    for (std::uint64_t seed = 1; seed <= 100; ++seed) {
      cost.push_back(run(context(), a, sc, seed, mc).cost);
      const RunResult r = run(context(), a, sc, seed, an);
      ASSERT_EQ(r.analytic_refusal, "") << name(a);
      analytic.push_back(r.analytic.total());
      diff.push_back(cost.back() - analytic.back());
    }
    const util::Summary c = util::summarize(cost);
    const util::Summary e = util::summarize(analytic);
    const util::Summary d = util::summarize(diff);
    std::printf("%s: MC %.6f ± %.6f, analytic %.6f ± %.6f, paired MC − analytic %.6f ± %.6f\n", name(a), c.mean, c.ci95,
                e.mean, e.ci95, d.mean, d.ci95);
    EXPECT_LT(std::fabs(e.mean - c.mean), c.ci95) << name(a);
    EXPECT_LT(std::fabs(d.mean), d.ci95) << name(a);
    EXPECT_LT(e.ci95, c.ci95) << name(a);  // the noise no longer adds to the interval
  }
}

/// One timing draw, the noise alone drawn again and again: the sharpest check of the
/// covariance maps (half Kalman, StandardKalman probe, S+'s memory, the filterless predictor).
TEST(NcsAnalytic, OneTimingDrawAgainstAMonteCarloOverTheNoiseAlone) {
  const Scenario sc = short_scenario(0.2, 8, 16, 2);
  RunOptions an;
  an.analytic = true;
  for (const Approach a : {Approach::kA, Approach::kAK, Approach::kSK, Approach::kSPlus}) {
    const RunResult r = run(context(), a, sc, 7, an);
    ASSERT_EQ(r.analytic_refusal, "") << name(a);
    std::vector<double> cost;
    RunOptions mc;
    // 1000 noise draws; a quarter under the sanitizers.
    for (std::uint64_t n = 1; n <= test::sanitized_length<std::uint64_t>(1000, 4); ++n) {
      mc.noise_seed = 1000 + n;
      cost.push_back(run(context(), a, sc, 7, mc).cost);
    }
    const util::Summary c = util::summarize(cost);
    std::printf("%s, timing seed 7: MC over the noise %.6f ± %.6f (%.2f %%), analytic %.6f\n", name(a), c.mean, c.ci95,
                100 * c.ci95 / c.mean, r.analytic.total());
    EXPECT_LT(std::fabs(r.analytic.total() - c.mean), c.ci95) << name(a);
  }
}

TEST(NcsAnalytic, NonLinearRunsAreRefusedWithTheReason) {
  RunOptions an;
  an.analytic = true;
  // A 4 V step drives the command into the ±1.65 V clamp: no longer affine.
  const RunResult big = run(context(), Approach::kAK, short_scenario(4, 8, 1, 2), 1, an);
  EXPECT_GT(big.saturated, 0U);
  EXPECT_EQ(big.analytic_refusal, "the noise-free trajectory reaches the actuator's clamp");
  // Chains longer than h: late commands.
  const RunResult late = run(context(), Approach::kA, short_scenario(0.5, 40, 1, 2), 1, an);
  EXPECT_GT(late.late, 0U);
  EXPECT_NE(late.analytic_refusal, "");
  RunOptions faulty = an;
  faulty.faults = engine::parse_fault_spec("dup:link=sc,rate=0.5");
  EXPECT_NE(run(context(), Approach::kA, short_scenario(0.5, 8, 1, 1), 1, faulty).analytic_refusal, "");
  EXPECT_EQ(analytic_refusal_code(""), 0);
  EXPECT_STREQ(analytic_refusal_text(analytic_refusal_code(big.analytic_refusal)), big.analytic_refusal.c_str());
}

TEST(NcsAnalytic, TableReportsTheAnalyticKeys) {
  TableOptions t;
  t.seeds = 3;
  t.threads = 1;
  t.analytic = true;
  t.approaches = {Approach::kI, Approach::kA, Approach::kAK, Approach::kSK};
  t.scenarios = {short_scenario(0.5, 8, 4, 2)};
  const nlohmann::json j = table_outputs(table_sweep(context(), t, engine::Shard{}), testing::TempDir() + "ncs_analytic",
                                         false);
  for (const char* a : {"A", "AK", "SK"}) {
    const auto& e = j.at("approaches").at(a);
    EXPECT_GT(e.at("analytic_mean").get<double>(), 0) << a;
    EXPECT_GT(e.at("analytic_ci95").get<double>(), 0) << a;
    EXPECT_GT(e.at("variance_reduction").get<double>(), 0) << a;
    EXPECT_TRUE(e.contains("cost_mean") && e.contains("cost_ci95") && e.contains("mc_minus_analytic_ci95"));
  }
  // The filters' cost hardly depends on the delays: the noise was nearly all of the interval.
  EXPECT_GT(j.at("approaches").at("AK").at("variance_reduction").get<double>(), 100);
  // SK's cost varies with the delays it does not model: the table's figure (the smallest) is its.
  EXPECT_EQ(j.at("variance_reduction").get<double>(), j.at("approaches").at("SK").at("variance_reduction").get<double>());
}

}  // namespace
}  // namespace oneshot::ncs
