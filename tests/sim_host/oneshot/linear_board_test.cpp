/// @file linear_board_test.cpp
/// @brief The linear board of study 000 and its analytic mode: noise-free analytic = simulated,
///        analytic mean against the Monte Carlo of the same model (paired per seed), the periodic
///        zero-delay loop (approach A) against the stationary LQG cost rate, the 0.2 % rule.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "board_events.hpp"
#include "linear_board.hpp"
#include "linear_tracker.hpp"
#include "oneshot/design/fixed_size.hpp"
#include "oneshot/engine/jump_linear_cost.hpp"
#include "oneshot/engine/stationary_cost.hpp"
#include "oneshot/util/statistics.hpp"
#include "scenario.hpp"
#include "simulation.hpp"
#include "table1_analytic.hpp"
#include "support/build_flavor.hpp"

namespace oneshot::sim {
namespace {

RunOptions double_options(Approach a) {
  RunOptions o;
  o.approach = a;
  o.format = NumberFormat::kDouble;
  return o;
}

/// A board run's whole periods (rounded down) and their end, the same for both boards.
TEST(BoardPeriods, WholePeriodsRoundedDownAndTheirEnd) {
  const engine::Duration h = engine::from_us(50'000);
  const BoardPeriods exact = board_periods(1.0, h);
  EXPECT_EQ(exact.count, 20);
  EXPECT_EQ(exact.end.count(), 20 * h.count());
  const BoardPeriods part = board_periods(1.07, h);  // 21.4 periods
  EXPECT_EQ(part.count, 21);
  EXPECT_EQ(part.end.count(), 21 * h.count());
  const BoardPeriods none = board_periods(0.01, h);
  EXPECT_EQ(none.count, 0);
  EXPECT_EQ(none.end.count(), 0);
}

TEST(LinearBoard, NoiseFreeAnalyticEqualsSimulatedOnEveryApproach) {
  const auto ctx = SimContext::reference();
  const Scenario sc = uniform_scenario("t", 20'000, 0.2, 1.0, 6.0);
  for (Approach a : kAllApproaches) {
    if (!approach_available(*ctx, a)) continue;
    for (std::uint64_t seed : {3U, 11U}) {
      const LinearRunResult r = run_linear_board(*ctx, sc, seed, double_options(a), LinearOptions{false, true});
      EXPECT_EQ(r.refusal, "") << info(a).letter;
      EXPECT_EQ(r.jobs, 120U);
      EXPECT_LT(r.mismatch, 1e-9);
      EXPECT_GT(r.cost, 0);
      EXPECT_NEAR(r.analytic.total(), r.cost, 1e-9 * r.cost) << info(a).letter << " seed " << seed;
      EXPECT_EQ(r.analytic.covariance, 0.0);
      // The same run without the tracker gives the same trajectory.
      const LinearRunResult s = run_linear_board(*ctx, sc, seed, double_options(a), LinearOptions{false, false});
      EXPECT_EQ(s.cost, r.cost);
    }
  }
}

TEST(LinearBoard, SameTimingDrawsAsTheEmulatedBoard) {
  // Same seed: the same jobs at the same sampling instants with the same τ, and with everything
  // but the PWM/ADC equal the costs stay close (quantization is small against the set-point steps).
  const auto ctx = SimContext::reference();
  const Scenario sc = uniform_scenario("t", 20'000, 0.5, 1.0, 4.0);
  for (Approach a : {Approach::kA, Approach::kB}) {
    RunOptions o = double_options(a);
    o.record_jobs = true;
    const RunResult board = simulate(*ctx, sc, 5, o);
    const LinearRunResult lin = run_linear_board(*ctx, sc, 5, o, LinearOptions{true, false, true});
    ASSERT_EQ(lin.jobs, board.jobs);
    ASSERT_EQ(lin.job_records.size(), board.job_records.size());
    ASSERT_GT(lin.job_records.size(), 0U);
    for (std::size_t k = 0; k < lin.job_records.size(); ++k) {
      EXPECT_EQ(lin.job_records[k].t_sample_s, board.job_records[k].t_sample_s) << info(a).letter << " job " << k;
      EXPECT_EQ(lin.job_records[k].tau_us, board.job_records[k].tau_us) << info(a).letter << " job " << k;
    }
    // Measured |board − linear| / board at seed 5: 1.8e-3 (A), 2.0e-4 (B): tolerance 5e-3.
    EXPECT_NEAR(lin.cost, board.cost.total(), 5e-3 * board.cost.total()) << info(a).letter;
  }
}

TEST(LinearBoard, AnalyticMeanAgreesWithTheMonteCarloOfTheSameModelPairedPerSeed) {
  // Paired per seed (the same timing and set-point draws): d_k = MC_k − analytic_k carries only
  // the noise, so |mean(d)| <= 3 se(d) tests the analytic mean at the noise's resolution.
  // Measured |mean(d)| / se(d), approaches A B C D E: small 0.41 0.19 0.19 0.66 0.73,
  // large 1.25 0.68 0.68 0.48 0.95.
  const auto ctx = SimContext::reference();
  // Two scenarios: noise-dominated small steps with 20 ms jitter, larger steps with 5 ms.
  // A quarter of the seeds under the sanitizers (the same paths, checked for memory and UB).
  constexpr std::size_t kDiv = 4;
  for (const auto& [sc, seeds] :
       {std::pair{uniform_scenario("small", 20'000, 0.2, 0.5, 2.0), test::sanitized_length<std::size_t>(1000, kDiv)},
        std::pair{uniform_scenario("large", 5'000, 0.8, 1.0, 3.0), test::sanitized_length<std::size_t>(300, kDiv)}}) {
    for (Approach a : kAllApproaches) {
      if (!approach_available(*ctx, a)) continue;
      std::vector<double> d;
      for (std::uint64_t seed = 1; seed <= seeds; ++seed) {
        const LinearRunResult r = run_linear_board(*ctx, sc, seed, double_options(a), LinearOptions{true, true});
        ASSERT_EQ(r.refusal, "") << sc.name << " " << info(a).letter;
        d.push_back(run_linear_board(*ctx, sc, seed, double_options(a), LinearOptions{true, false}).cost - r.analytic.total());
      }
      double mean = 0;
      for (double x : d) mean += x;
      mean /= static_cast<double>(d.size());
      double ss = 0;
      for (double x : d) ss += (x - mean) * (x - mean);
      const double se = std::sqrt(ss / static_cast<double>(d.size() - 1) / static_cast<double>(d.size()));
      EXPECT_LE(std::fabs(mean), 3 * se) << sc.name << " " << info(a).letter;
    }
  }
}

TEST(LinearBoard, PeriodicZeroDelayLoopEqualsTheStationaryLqgCostRate) {
  // Approach A: sample, estimate and actuate at t_k (no jitter, zero execution time), the
  // standard Kalman filter started at its steady-state prior. Oracle: the closed loop
  // z = [x; u; x̂] over one period from the design's matrices (steady-state gain K, LQR L),
  // its stationary covariance from engine::stationary_cost (a Lyapunov solve).
  const auto ctx = SimContext::reference();
  const design::PlantDescription& plant = ctx->plant();
  const design::DesignResult& d = ctx->design();
  constexpr std::size_t N = 2;
  constexpr std::size_t M = 1;
  constexpr std::size_t P = 1;
  constexpr std::size_t K = N + M + N;
  ASSERT_EQ(plant.n(), N);
  const auto c = design::to_fixed<double, P, N>(plant.c);
  const auto phi = design::to_fixed<double, N, N>(d.phi_h);
  const auto gamma = design::to_fixed<double, N, M>(d.gamma_h);
  const auto kg = design::to_fixed<double, N, P>(d.kalman_gain);
  const auto l = design::to_fixed<double, M, N>(d.l);
  const engine::JumpLinearPlant<N, M> jp{design::to_fixed<double, N, N>(plant.a), design::to_fixed<double, N, M>(plant.b),
                                         design::to_fixed<double, N, N>(d.qc), design::to_fixed<double, N, N>(plant.q1c),
                                         design::to_fixed<double, M, M>(plant.q2c)};
  Matrix<double, P, P> r;
  r(0, 0) = plant.measurement_covariance(0, 0);
  // Job: x̂⁺ = (I − K C)(Φ x̂ + Γ u) + K (C x + v), u⁺ = −L x̂⁺.
  Matrix<double, K, K> e = Matrix<double, K, K>::identity();
  Matrix<double, K, P> f;
  const Matrix<double, N, N> ikc = Matrix<double, N, N>::identity() - kg * c;
  const Matrix<double, N, N> a_h = ikc * phi;
  const Matrix<double, N, M> b_h = ikc * gamma;
  const Matrix<double, N, N> kc = kg * c;
  for (std::size_t i = 0; i < N; ++i) {
    for (std::size_t j = 0; j < K; ++j) e(N + M + i, j) = 0;
    for (std::size_t j = 0; j < N; ++j) {
      e(N + M + i, j) = kc(i, j);
      e(N + M + i, N + M + j) = a_h(i, j);
    }
    for (std::size_t j = 0; j < M; ++j) e(N + M + i, N + j) = b_h(i, j);
    for (std::size_t p = 0; p < P; ++p) f(N + M + i, p) = kg(i, p);
  }
  Matrix<double, K, K> e_u = Matrix<double, K, K>::identity();  // u ← −L x̂ (after the estimate)
  for (std::size_t j = 0; j < M; ++j) {
    e_u(N + j, N + j) = 0;
    for (std::size_t i = 0; i < N; ++i) e_u(N + j, N + M + i) = -l(j, i);
  }
  const engine::Duration h = engine::from_us(plant.period_us);
  const auto run = [&](std::size_t, const Matrix<double, K, K>& s) {
    engine::JumpLinearCost<N, M, K> jl(jp);
    jl.reset(Vector<double, K>{}, s);
    jl.jump(e, f, Vector<double, K>{}, r);
    jl.jump(e_u, Vector<double, K>{});
    jl.flow(h);
    return engine::PeriodOutcome<K>{jl.covariance(), jl.cost().total()};
  };
  const engine::StationaryCost st = engine::stationary_cost<K>({1.0}, {engine::to_seconds(h)}, run);
  ASSERT_GT(st.cost_rate, 0);

  Scenario sc = uniform_scenario("still", 0, 0.0, 1000.0, 200.0);
  const LinearRunResult full = run_linear_board(*ctx, sc, 1, double_options(Approach::kA), LinearOptions{true, true});
  sc.duration_s = 100.0;
  const LinearRunResult half = run_linear_board(*ctx, sc, 1, double_options(Approach::kA), LinearOptions{true, true});
  ASSERT_EQ(full.refusal, "");
  ASSERT_EQ(half.refusal, "");
  const double rate = (full.analytic.total() - half.analytic.total()) / 100.0;
  EXPECT_NEAR(rate, st.cost_rate, 1e-9 * st.cost_rate);
}

TEST(LinearBoard, NoRunOfTheLargestStepsLeavesTheActuatorRange) {
  // Steps across the whole ADC range (±1.6 V of ±1.65 V) stay inside the ±1.65 V PWM on the
  // reference board: the analytic mode is refused exactly when the noise-free input leaves it.
  const auto ctx = SimContext::reference();
  const Scenario sc = uniform_scenario("big", 20'000, 1.6, 0.5, 4.0);
  for (Approach a : kAllApproaches) {
    for (std::uint64_t seed = 1; seed <= 5; ++seed) {
      const LinearRunResult r = run_linear_board(*ctx, sc, seed, double_options(a), LinearOptions{true, true});
      const LinearRunResult s = run_linear_board(*ctx, sc, seed, double_options(a), LinearOptions{false, false});
      EXPECT_EQ(s.out_of_range, 0U) << info(a).letter << seed;
      EXPECT_EQ(r.refusal, "") << info(a).letter << seed;
    }
  }
}

TEST(LinearTracker, RefusesAnInputOutsideTheRangeAndAMeanOffTheSimulatedRun) {
  // One state, ẋ = −x + u; a job x̂ ← y, u = 2 y + 1 (affine): at x = 0 it asks for u = 1.
  engine::JumpLinearPlant<1, 1> p;
  p.a(0, 0) = -1;
  p.b(0, 0) = 1;
  p.q1c(0, 0) = 1;
  p.q2c(0, 0) = 1;
  Matrix<double, 1, 1> c;
  c(0, 0) = 1;
  const auto eval = [](const Vector<double, 4>& w) { return Vector<double, 2>({w[0], 2 * w[0] + 1}); };
  LinearTracker<1, 1, 1> inside(p, c, Matrix<double, 1, 1>{}, Vector<double, 1>{}, Vector<double, 1>({-2.0}),
                                Vector<double, 1>({2.0}));
  inside.job(eval, Vector<double, 1>{}, Vector<double, 1>({1.0}));
  EXPECT_EQ(inside.refusal(), "");
  constexpr std::size_t kL = LinearTracker<1, 1, 1>::kL;
  EXPECT_DOUBLE_EQ(inside.mean()[kL], 1.0);
  inside.apply(Vector<double, 1>({1.0}));
  inside.flow_to(engine::SimTime{1'000'000'000});
  // x(1) = 1 − e^{−1} under u = 1 from x = 0.
  EXPECT_NEAR(inside.mean()[0], 1 - std::exp(-1.0), 1e-12);
  LinearTracker<1, 1, 1> narrow(p, c, Matrix<double, 1, 1>{}, Vector<double, 1>{}, Vector<double, 1>({-0.5}),
                                Vector<double, 1>({0.5}));
  narrow.job(eval, Vector<double, 1>{}, Vector<double, 1>({1.0}));
  EXPECT_EQ(narrow.refusal(), kLinearRefusalRange);
  LinearTracker<1, 1, 1> off(p, c, Matrix<double, 1, 1>{}, Vector<double, 1>{}, Vector<double, 1>({-2.0}),
                             Vector<double, 1>({2.0}));
  off.job(eval, Vector<double, 1>{}, Vector<double, 1>({1.001}));
  EXPECT_EQ(off.refusal(), kLinearRefusalMismatch);
}

TEST(Table1Analytic, WithinRuleDecidesOnTheWholeInterval) {
  EXPECT_STREQ(decide_within(0.001, 0.0005, 0.002), "yes");
  EXPECT_STREQ(decide_within(0.003, 0.0005, 0.002), "no");
  EXPECT_STREQ(decide_within(0.0022, 0.0020, 0.002), "undecided");
  EXPECT_STREQ(decide_within(-0.01, 0.001, 0.002), "yes");
}

}  // namespace
}  // namespace oneshot::sim
