/// @file stationary_cost_test.cpp
/// @brief stationary_cost() against closed forms (a scalar jump-linear recursion; periodic LQG's
///        stationary cost rate), a brute-force fixed-point iteration and a long run over random
///        timing on JumpLinearCost; an unstable mixture is refused.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <vector>

#include "oneshot/engine/random_stream.hpp"
#include "oneshot/engine/stationary_cost.hpp"
#include "support/periodic_lqg_loop.hpp"

namespace oneshot::engine {
namespace {

using namespace lqg_fixture;  // NOLINT: the fixture of this file

/// Scalar recursion z⁺ = a_i z + w, w ~ N(0, q_i), cost z² per period: Σ = Σp q / (1 − Σp a²).
TEST(StationaryCost, ScalarMixtureEqualsTheClosedForm) {
  const std::vector<double> a = {0.5, 0.9, 1.1};
  const std::vector<double> q = {1.0, 2.0, 0.5};
  const std::vector<double> p = {0.2, 0.5, 0.3};
  const auto run = [&](std::size_t i, const Matrix<double, 1, 1>& s) {
    PeriodOutcome<1> o;
    o.sigma(0, 0) = a[i] * a[i] * s(0, 0) + q[i];
    o.cost = s(0, 0);
    return o;
  };
  const StationaryCost r = stationary_cost<1>(p, {0.1, 0.1, 0.1}, run);
  double pq = 0;
  double pa2 = 0;
  for (std::size_t i = 0; i < 3; ++i) {
    pq += p[i] * q[i];
    pa2 += p[i] * a[i] * a[i];
  }
  const double sigma = pq / (1 - pa2);
  EXPECT_NEAR(r.sigma(0, 0) / sigma - 1, 0, 1e-14);
  EXPECT_NEAR(r.cost_rate / (sigma / 0.1) - 1, 0, 1e-14);
  EXPECT_NEAR(r.spectral_radius, pa2, 1e-15);
  EXPECT_LT(r.residual, 1e-14);
}

TEST(StationaryCost, UnstableMixtureIsRefusedNamingTheSpectralRadius) {
  const auto run = [](std::size_t i, const Matrix<double, 1, 1>& s) {
    PeriodOutcome<1> o;
    const double a = i == 0 ? 0.5 : 1.5;  // Σp a² = 0.5·0.25 + 0.5·2.25 = 1.25
    o.sigma(0, 0) = a * a * s(0, 0) + 1;
    o.cost = s(0, 0);
    return o;
  };
  try {
    (void)stationary_cost<1>({0.5, 0.5}, {1, 1}, run);
    FAIL() << "an unstable mixture must be refused";
  } catch (const std::domain_error& e) {
    EXPECT_NE(std::string(e.what()).find("spectral radius"), std::string::npos) << e.what();
  }
  EXPECT_THROW((void)stationary_cost<1>({0.5, 0.4}, {1, 1}, run), std::invalid_argument);  // Σp ≠ 1
}

/// z = [x; spare]: x⁺ = 0.5 x + w, the spare slot never written (kept as it is).
TEST(StationaryCost, DeadRegisterIsLeftOutOnlyWhenItMovesNothing) {
  const auto run = [](std::size_t, const Matrix<double, 2, 2>& s) {
    PeriodOutcome<2> o;
    o.sigma(0, 0) = 0.25 * s(0, 0) + 1;
    o.sigma(1, 1) = s(1, 1);  // spare: identity, eigenvalue 1
    o.cost = s(0, 0);
    return o;
  };
  EXPECT_THROW((void)stationary_cost<2>({1.0}, {1.0}, run), std::domain_error);
  const StationaryCost r = stationary_cost<2>({1.0}, {1.0}, run, {true, false});
  EXPECT_NEAR(r.sigma(0, 0), 1 / 0.75, 1e-15);
  EXPECT_EQ(r.sigma(1, 1), 0);
  // Declared dead but read by x: refused.
  const auto coupled = [](std::size_t, const Matrix<double, 2, 2>& s) {
    PeriodOutcome<2> o;
    o.sigma(0, 0) = 0.25 * s(0, 0) + 0.1 * s(1, 1) + 1;
    o.sigma(1, 1) = s(1, 1);
    o.cost = s(0, 0);
    return o;
  };
  EXPECT_THROW((void)stationary_cost<2>({1.0}, {1.0}, coupled, {true, false}), std::logic_error);
}

/// One period of the LQG loop: the sampling event, then a flow of `len`.
PeriodOutcome<kK> lqg_period(Jlc& jl, const EventMap& m, const Matrix<double, 1, 1>& r, Duration len,
                             const Matrix<double, kK, kK>& s) {
  jl.reset(Jlc::Z{}, s);
  jl.clear_cost();
  jl.jump(m.e, m.f, m.g, r);
  jl.flow(len);
  return {jl.covariance(), jl.cost().covariance + jl.cost().noise_path};
}

TEST(StationaryCost, PeriodicLqgEqualsTheClosedFormRate) {
  LqgSetup setup;
  const Loop& p = setup.p;
  const auto run = [&](std::size_t, const Matrix<double, kK, kK>& s) {
    return lqg_period(setup.jl, setup.m, setup.r, from_us(100000), s);
  };
  const StationaryCost st = stationary_cost<kK>({1.0}, {p.h}, run);
  const MatX w = p.gc.bottomRightCorner(1, 1) + p.gamma.transpose() * p.s * p.gamma;
  const double closed = ((p.s * p.qd).trace() + (p.pf * p.l.transpose() * w * p.l).trace() + noise_path(p, p.h)) / p.h;
  std::printf("stationary LQG rate %.15g closed %.15g rel %.3g rho %.6f\n", st.cost_rate, closed, st.cost_rate / closed - 1,
              st.spectral_radius);
  EXPECT_NEAR(st.cost_rate / closed - 1, 0, 1e-13);  // measured 2e-15 (brief: 1e-9)
}

/// Sampling intervals 0.8 h, h, 1.3 h with probabilities 0.3, 0.5, 0.2 (the filter and gain stay those of h).
struct Jittered : LqgSetup {
  std::vector<double> prob = {0.3, 0.5, 0.2};
  std::vector<std::int64_t> len_us = {80000, 100000, 130000};
  PeriodOutcome<kK> period(std::size_t i, const Matrix<double, kK, kK>& s) { return lqg_period(jl, m, r, from_us(len_us[i]), s); }
  std::vector<double> lengths() const { return {0.08, 0.1, 0.13}; }
};

TEST(StationaryCost, JitteredLqgEqualsAFixedPointIteration) {
  Jittered j;
  const StationaryCost st = stationary_cost<kK>(j.prob, j.lengths(), [&](std::size_t i, const auto& s) { return j.period(i, s); });
  // Brute force: Σ ← Σ_i p_i Σ'_i(Σ) until it stops moving, cost at the limit.
  Matrix<double, kK, kK> s{};
  double cost = 0;
  for (int it = 0; it < 20000; ++it) {
    Matrix<double, kK, kK> next{};
    cost = 0;
    for (std::size_t i = 0; i < 3; ++i) {
      const PeriodOutcome<kK> o = j.period(i, s);
      next = next + o.sigma * j.prob[i];
      cost += j.prob[i] * o.cost;
    }
    s = next;
  }
  double worst = 0;
  for (std::size_t a = 0; a < kK; ++a)
    for (std::size_t b = 0; b < kK; ++b) worst = std::fmax(worst, std::fabs(s(a, b) - st.sigma(a, b)));
  const double rate = cost / (0.3 * 0.08 + 0.5 * 0.1 + 0.2 * 0.13);
  std::printf("jittered: rate %.15g iteration %.15g rel %.3g, max |dSigma| %.3g, rho %.6f\n", st.cost_rate, rate,
              st.cost_rate / rate - 1, worst, st.spectral_radius);
  EXPECT_NEAR(st.cost_rate / rate - 1, 0, 1e-14);  // measured 1e-16
  EXPECT_LT(worst, 1e-15);  // measured 4e-17 (entries ~1e-3)
}

TEST(StationaryCost, JitteredLqgInsideALongRandomRun) {
  Jittered j;
  const StationaryCost st = stationary_cost<kK>(j.prob, j.lengths(), [&](std::size_t i, const auto& s) { return j.period(i, s); });
  // 40 batches of 5000 periods with the interval drawn i.i.d. per period; rate per batch.
  RandomStream rng(7, "timing");
  Jlc jl(engine_plant(j.p, true));
  for (int i = 0; i < 200; ++i) {  // warm-up from rest
    jl.jump(j.m.e, j.m.f, j.m.g, j.r);
    jl.flow(from_us(100000));
  }
  std::vector<double> rates;
  for (int b = 0; b < 40; ++b) {
    jl.clear_cost();
    double t = 0;
    for (int k = 0; k < 5000; ++k) {
      const double u = rng.uniform01();
      const std::size_t i = u < 0.3 ? 0 : (u < 0.8 ? 1 : 2);
      jl.jump(j.m.e, j.m.f, j.m.g, j.r);
      jl.flow(from_us(j.len_us[i]));
      t += static_cast<double>(j.len_us[i]) * 1e-6;
    }
    rates.push_back((jl.cost().covariance + jl.cost().noise_path) / t);
  }
  double mean = 0;
  for (double x : rates) mean += x;
  mean /= static_cast<double>(rates.size());
  double var = 0;
  for (double x : rates) var += (x - mean) * (x - mean);
  const double ci = 2.02 * std::sqrt(var / static_cast<double>(rates.size() - 1) / static_cast<double>(rates.size()));
  std::printf("jittered: stationary %.6f long run %.6f +- %.6f\n", st.cost_rate, mean, ci);
  EXPECT_NEAR(mean, st.cost_rate, ci);
}

}  // namespace
}  // namespace oneshot::engine
