/// @file ncs_study_test.cpp
/// @brief Study `ncs` on the engine: the noise-free invariant (A = I for any delays that fit
///        in h, S degrading as d grows), late commands counted when the chain exceeds h,
///        the S+ design against the LQR, determinism, traces, the table's fields.
#include <gtest/gtest.h>

#include <cmath>
#include <optional>
#include <stdexcept>
#include <string>

#include "ncs_experiments.hpp"
#include "ncs_loop.hpp"
#include "ncs_model.hpp"
#include "ncs_test_support.hpp"

namespace oneshot::ncs {
namespace {

/// Noise-free: A predicts the sampled state exactly to t_k, so it is I for any delays that
/// fit in h; S pays for its delay, more as d grows.
TEST(NcsStudy, NoiseFreeAEqualsIAndSDegradesWithDelay) {
  RunOptions nf;
  nf.noise_free = true;
  double worst = 0;
  double s_prev = 1;
  for (double d : {4.0, 8.0, 14.0}) {
    double s_ratio = 0;
    for (std::uint64_t seed = 1; seed <= 3; ++seed) {
      const Scenario sc = short_scenario(0.5, d);
      const RunResult i = run(context(), Approach::kI, sc, seed, nf);
      const RunResult a = run(context(), Approach::kA, sc, seed, nf);
      const RunResult s = run(context(), Approach::kS, sc, seed, nf);
      worst = std::fmax(worst, std::fabs(a.cost / i.cost - 1));
      EXPECT_EQ(a.late, 0U);
      EXPECT_EQ(a.commands + 1, i.commands);  // I also applies u_0 at t = 0; A has no command for k = 0
      s_ratio += s.cost / i.cost / 3;
    }
    EXPECT_GT(s_ratio, s_prev + 1e-4) << "d = " << d;  // S degrades as d grows
    s_prev = s_ratio;
  }
  EXPECT_LT(worst, 1e-14);  // issue: 1e-9; measured 4.4e-16 (1.8e-15 over the full noise-free table)
}

/// With legs up to 40 ms the chain exceeds h: commands are late, held, counted, and the loop
/// still runs on the echoed inputs.
TEST(NcsStudy, LateCommandsAreCountedWhenTheChainExceedsThePeriod) {
  const Scenario sc = short_scenario(0.5, 40);
  const RunResult ak = run(context(), Approach::kAK, sc, 5, RunOptions{});
  EXPECT_GT(ak.late, 0U);
  EXPECT_LT(ak.late, 60U);
  EXPECT_EQ(ak.commands + ak.late + 1, 60U);  // 60 timer interrupts at 0 … 2.95 s, the first has no command
  EXPECT_TRUE(std::isfinite(ak.cost));
  const RunResult fits = run(context(), Approach::kAK, short_scenario(0.5, 14), 5, RunOptions{});
  EXPECT_EQ(fits.late, 0U);  // 3·14 + 5 = 47 ms < h
}

/// The sc + ca delay bound of study-file legs: the sum of the legs' largest delays (the oracle:
/// the uniform maxima given), none naming the leg when one is unbounded; AKl's D adds τ_c,max.
TEST(NcsStudy, ScCaDelayBoundIsTheSumOfTheLegsMaximaOrNoneNamingTheLeg) {
  Scenario sc = short_scenario(0.5, 4);
  const auto uniform = [](std::int64_t min_us, std::int64_t max_us) {
    engine::LinkConfig c;
    c.delay.kind = engine::DelayModel::Kind::kUniform;
    c.delay.min = engine::from_us(min_us);
    c.delay.max = engine::from_us(max_us);
    return c;
  };
  sc.legs["as"] = uniform(500, 90'000);  // not part of the chain
  sc.legs["sc"] = uniform(500, 7'000);
  sc.legs["ca"] = uniform(1'000, 3'250);
  const std::optional<engine::Duration> ub = sc_ca_delay_bound(sc);
  ASSERT_TRUE(ub.has_value());
  EXPECT_EQ(ub->count(), engine::from_us(7'000 + 3'250).count());
  EXPECT_EQ(context().worst_chain_us(sc), 7'000 + 3'250 + context().timing().compute_max_us);
  sc.legs["ca"].delay.kind = engine::DelayModel::Kind::kLognormal;
  sc.legs["ca"].delay.median_ns = 1e6;
  sc.legs["ca"].delay.sigma = 0.5;
  const char* leg = nullptr;
  EXPECT_FALSE(sc_ca_delay_bound(sc, &leg).has_value());
  ASSERT_NE(leg, nullptr);
  EXPECT_STREQ(leg, "ca");
  try {
    static_cast<void>(context().worst_chain_us(sc));
    ADD_FAILURE() << "an unbounded leg was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("leg ca has no upper delay bound"), std::string::npos) << e.what();
  }
}

/// S+ at τ = 0 is the plain LQR: [L, 0].
TEST(NcsStudy, DelayCompensatedGainAtZeroDelayIsTheLqr) {
  const auto g = delay_compensated_gain(context(), 0);
  for (std::size_t j = 0; j < kN; ++j) EXPECT_NEAR(g[j], context().design().l(0, j), 5e-15);  // measured 7.8e-16
  EXPECT_NEAR(g[kN], 0, 5e-15);  // measured 0
  const auto g14 = delay_compensated_gain(context(), 17'500);
  EXPECT_GT(std::fabs(g14[kN]), 1e-3);  // a real delay gets a u_{k−1} term
}

TEST(NcsStudy, RunsAreDeterministicAndSeedsMatter) {
  const Scenario sc = short_scenario(0.2, 8, 4, 2);
  for (Approach a : kAllApproaches) {
    const double c1 = run(context(), a, sc, 11, RunOptions{}).cost;
    EXPECT_EQ(c1, run(context(), a, sc, 11, RunOptions{}).cost) << name(a);
    if (a != Approach::kI) {
      EXPECT_NE(c1, run(context(), a, sc, 12, RunOptions{}).cost) << name(a);
    }
  }
}

/// A trace (bridged from its own stream) never changes the run.
TEST(NcsStudy, TracingNeverChangesTheRun) {
  const Scenario sc = short_scenario(0.5, 8, 4, 2);
  RunOptions traced;
  traced.trace_step_s = 1e-3;
  for (Approach a : {Approach::kAK, Approach::kS}) {
    const RunResult r = run(context(), a, sc, 3, traced);
    EXPECT_EQ(r.cost, run(context(), a, sc, 3, RunOptions{}).cost);
    EXPECT_EQ(r.truth.size(), 2001U);
  }
}

TEST(NcsStudy, TheShippedScenarioFileIsTheBuiltInDefaultsAndBadFieldsAreNamed) {
  const std::vector<Scenario> file = load_scenarios(ONESHOT_NCS_SCENARIO_FILE);
  const std::vector<Scenario> builtin = default_scenarios();
  ASSERT_EQ(file.size(), builtin.size());
  for (std::size_t i = 0; i < file.size(); ++i) {
    EXPECT_EQ(file[i].name, builtin[i].name);
    EXPECT_EQ(file[i].amplitude_volts, builtin[i].amplitude_volts);
    EXPECT_EQ(file[i].period_s, builtin[i].period_s);
    EXPECT_EQ(file[i].max_delay_ms, builtin[i].max_delay_ms);
    EXPECT_EQ(file[i].noise_scale, builtin[i].noise_scale);
    EXPECT_EQ(file[i].duration_s, builtin[i].duration_s);
  }
  try {
    parse_scenarios(R"({"scenarios": [{"name": "x", "amplitude_volts": 1, "period_s": 2, "max_delay_ms": 0.1, "noise_scale": 1}]})",
                    "f.json");
    FAIL() << "a delay below 0.5 ms was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("max_delay_ms"), std::string::npos) << e.what();
  }
  EXPECT_THROW(parse_scenarios(R"({"scenarios": [{"name": "x", "bogus": 1}]})", "f.json"), std::invalid_argument);
}

TEST(NcsStudy, TableSummaryHasTheIssueFields) {
  TableOptions t;
  t.seeds = 2;
  t.duration_s = 2.5;  // every scenario switches its set-point at least once (I's cost > 0)
  t.threads = 1;
  t.approaches = {Approach::kI, Approach::kS, Approach::kA, Approach::kAK};
  const nlohmann::json j = table_outputs(table_sweep(context(), t, engine::Shard{}), testing::TempDir() + "ncs_table", false);
  for (const char* a : {"I", "S", "A", "AK"}) {
    for (const char* f : {"cost_mean", "cost_ci95", "ratio_to_I", "ratio_scenario_weighted", "ratio_scenario_weighted_ci95"}) {
      EXPECT_TRUE(j.at("approaches").at(a).contains(f)) << a << " " << f;
    }
  }
  EXPECT_EQ(j.at("approaches").at("I").at("ratio_to_I").get<double>(), 1.0);
  EXPECT_TRUE(j.at("paired_differences").contains("S-A"));
  EXPECT_EQ(j.at("per_scenario").size(), 10U);
  EXPECT_EQ(j.at("order_by_mean_cost").size(), 4U);
}

}  // namespace
}  // namespace oneshot::ncs
