/// @file jump_linear_cost_test.cpp
/// @brief JumpLinearCost against three oracles: the closed-form stationary LQG cost rate
///        (Riccati solutions, Eigen), a direct noise-free simulation (Eigen exponentials and
///        quadrature), and a Monte Carlo of the same loop on the engine's ContinuousPlant; the
///        shared caches, and the affine probe of the analytic modes.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include "oneshot/engine/affine_probe.hpp"
#include "oneshot/engine/continuous_plant.hpp"
#include "oneshot/engine/jump_linear_cost.hpp"
#include "oneshot/engine/random_stream.hpp"
#include "support/eigen_reference.hpp"
#include "support/periodic_lqg_loop.hpp"

namespace oneshot::engine {
namespace {

using namespace lqg_fixture;  // NOLINT: the fixture of this file

TEST(JumpLinearCost, PeriodicLqgEqualsTheClosedFormStationaryCostRate) {
  LqgSetup setup;
  const Loop& p = setup.p;
  Jlc& jl = setup.jl;
  const EventMap& m = setup.m;
  const Matrix<double, 1, 1>& r = setup.r;
  const Duration h = from_us(100000);
  const auto periods = [&](int n) {
    for (int i = 0; i < n; ++i) {
      jl.jump(m.e, m.f, m.g, r);
      jl.flow(h);
    }
  };
  periods(3000);
  const double before = jl.cost().total();
  periods(200);
  const double rate = (jl.cost().total() - before) / (200 * p.h);
  // Completion of squares: h·J = tr(S Q_d) + tr(P_f Lᵀ (Q2 + ΓᵀSΓ) L) + ∫₀^h tr(Q1c Q_d(s)) ds.
  const MatX w = p.gc.bottomRightCorner(1, 1) + p.gamma.transpose() * p.s * p.gamma;
  const double closed = ((p.s * p.qd).trace() + (p.pf * p.l.transpose() * w * p.l).trace() + noise_path(p, p.h)) / p.h;
  std::printf("LQG rate %.15g closed %.15g rel %.3g\n", rate, closed, rate / closed - 1);
  EXPECT_NEAR(rate / closed - 1, 0, 1e-9) << rate << " vs " << closed;
  EXPECT_NEAR(jl.cost().mean, 0, 1e-300);  // starts at rest on the reference
}

/// Irregular intervals around h (whole µs), the same for the analytic run and its oracles.
std::vector<std::int64_t> jittered_intervals_us(int n) {
  RandomStream rng(7, "intervals");
  std::vector<std::int64_t> d;
  for (int i = 0; i < n; ++i) d.push_back(80000 + 10000 * rng.uniform_int(0, 4));
  return d;
}

TEST(JumpLinearCost, NoiseFreeEqualsADirectSimulation) {
  const Loop p = designed();
  Jlc jl(engine_plant(p, false));
  Jlc::Z m0{};
  m0[0] = 1.0;
  m0[3] = 0.8;
  jl.reset(m0, Jlc::Cov{});
  const std::vector<std::int64_t> d = jittered_intervals_us(300);
  // Direct: x(t) by Eigen's exponential, ∫ by quadrature of the same (sampled_cost over each Δ).
  VecX x = (VecX(2) << 1.0, 0).finished();
  VecX xh = (VecX(2) << 0.8, 0).finished();
  double u = 0;
  double j_direct = 0;
  for (std::size_t i = 0; i < d.size(); ++i) {
    const double x_ref = i >= 150 ? 0.5 : 0.0;  // a set-point step halfway
    const double u_ref = 4 * x_ref;
    const VecX xr = (VecX(2) << x_ref, 0).finished();
    jl.set_reference(Vector<double, 2>({x_ref, 0}), Vector<double, 1>({u_ref}));
    const EventMap m = event_map(p, x_ref, u_ref);
    jl.jump(m.e, m.g);
    const VecX xf = xh + p.k * (p.c * x - p.c * xh);
    u = u_ref - (p.l * (xf - xr))(0);
    xh = p.phi * xf + p.gamma * u;
    const double t = static_cast<double>(d[i]) * 1e-6;
    jl.flow(from_us(d[i]));
    VecX q(3);
    q << x - xr, u - u_ref;
    j_direct += q.dot(sampled_cost(p, t) * q);
    const test::Triple tr = test::reference_triple(p.a, p.b, p.qc, t);
    x = xr + tr.phi * (x - xr) + tr.gamma * (u - u_ref);
  }
  std::printf("noise-free rel %.3g x %.3g\n", jl.cost().total() / j_direct - 1, jl.mean()[0] - x(0));
  EXPECT_NEAR(jl.cost().total() / j_direct - 1, 0, 1e-12);
  EXPECT_NEAR(jl.mean()[0], x(0), 1e-12);
  EXPECT_NEAR(jl.mean()[4], xh(1), 1e-12);
  EXPECT_EQ(jl.cost().covariance, 0);
  EXPECT_EQ(jl.cost().noise_path, 0);
}

TEST(JumpLinearCost, WithNoiseInsideTheMonteCarloInterval) {
  const Loop p = designed();
  Jlc jl(engine_plant(p, true));
  Jlc::Z m0{};
  m0[0] = 0.5;
  jl.reset(m0, Jlc::Cov{});
  const std::vector<std::int64_t> d = jittered_intervals_us(40);
  const EventMap m = event_map(p, 0, 0);
  Matrix<double, 1, 1> r;
  r(0, 0) = p.r;
  for (const std::int64_t di : d) {
    jl.jump(m.e, m.f, m.g, r);
    jl.flow(from_us(di));
  }
  // Monte Carlo of the same loop: the engine's plant (exact process-noise draws) and drawn v.
  ContinuousPlantConfig<2, 1, 1, 1> cfg;
  const JumpLinearPlant<2, 1> ep = engine_plant(p, true);
  cfg.a = ep.a;
  cfg.b = ep.b;
  cfg.qc = ep.qc;
  cfg.q1c = ep.q1c;
  cfg.q2c = ep.q2c;
  cfg.c(0, 0) = 1;
  const int runs = 1500;
  double sum = 0;
  double sum2 = 0;
  RandomStream meas(11, "measurement");
  for (int run = 0; run < runs; ++run) {
    ContinuousPlant<2, 1, 1, 1> plant(cfg, RandomStream(static_cast<std::uint64_t>(run), "process"));
    plant.set_state(Vector<double, 2>({0.5, 0}));
    VecX xh = VecX::Zero(2);
    SimTime t{0};
    for (const std::int64_t di : d) {
      plant.advance_to(t);
      const double y = plant.output()[0] + std::sqrt(p.r) * meas.normal();
      const VecX xf = xh + p.k * (y - (p.c * xh)(0));
      const double u = -(p.l * xf)(0);
      xh = p.phi * xf + p.gamma * u;
      plant.set_input(Vector<double, 1>({u}));
      t += from_us(di);
    }
    plant.advance_to(t);
    const double j = plant.cost().total();
    sum += j;
    sum2 += j * j;
  }
  const double mean = sum / runs;
  const double sd = std::sqrt((sum2 - runs * mean * mean) / (runs - 1));
  const double half = 1.96 * sd / std::sqrt(static_cast<double>(runs));
  std::printf("mc %.6g analytic %.6g half %.3g\n", mean, jl.cost().total(), half);
  EXPECT_LT(std::fabs(jl.cost().total() - mean), half) << jl.cost().total() << " vs " << mean << " ± " << half;
  EXPECT_GT(jl.cost().covariance + jl.cost().noise_path, 0.2 * jl.cost().total());  // noise matters here
}

TEST(JumpLinearCost, EventCostIsTheQuadraticMeanPlusTheTrace) {
  // z = m + chol·n: E[(z − c)ᵀ W (z − c)] by its definition over a Monte Carlo of 20000 draws.
  Jlc jl(engine_plant(designed(), true));
  Jlc::Z m({1, -0.5, 0.2, 0.3, 0});
  Jlc::Cov l;  // lower factor
  RandomStream rng(3, "factor");
  for (std::size_t i = 0; i < kK; ++i)
    for (std::size_t j = 0; j <= i; ++j) l(i, j) = rng.uniform(-0.5, 0.5) + (i == j ? 1 : 0);
  jl.reset(m, l * l.transposed());
  Jlc::Map w;
  for (std::size_t i = 0; i < kK; ++i) w(i, i) = 1 + static_cast<double>(i);
  w(0, 1) = w(1, 0) = 0.3;
  Jlc::Z c({0.5, 0, 0, 0, 1});
  jl.add_event_cost(w, c);
  double sum = 0;
  double sum2 = 0;
  const int n = 20000;
  RandomStream draws(4, "draws");
  for (int k = 0; k < n; ++k) {
    Jlc::Z v;
    for (std::size_t i = 0; i < kK; ++i) v[i] = draws.normal();
    const double q = quadratic_form(w, Jlc::Z(m + l * v - c));
    sum += q;
    sum2 += q * q;
  }
  const double mean = sum / n;
  const double half = 1.96 * std::sqrt((sum2 - n * mean * mean) / (n - 1) / n);
  EXPECT_LT(std::fabs(jl.cost().total() - mean), half) << jl.cost().total() << " vs " << mean << " ± " << half;
  EXPECT_NEAR(jl.cost().mean, quadratic_form(w, Jlc::Z(m - c)), 1e-15);
}

TEST(JumpLinearCost, SharedCachesGiveTheSameResultsBitForBit) {
  // Caches shared by runs (the linear board's per-thread caches) hold the same values per
  // interval length: a run on them equals a run on its own caches, whatever ran before.
  LqgSetup setup;
  const JumpLinearPlant<kN, kM> ep = engine_plant(setup.p, true);
  ExactSegmentCache<kN, kM> segments(ep.a, ep.b, ep.q1c);
  ProcessNoise<kN> noise(ep.a, ep.qc, ep.q1c);
  const std::vector<std::int64_t> d = jittered_intervals_us(200);
  for (int pass = 0; pass < 2; ++pass) {
    Jlc own(ep);
    Jlc shared(ep, segments, noise);
    for (std::int64_t us : d) {
      for (Jlc* j : {&own, &shared}) {
        j->jump(setup.m.e, setup.m.f, setup.m.g, setup.r);
        j->flow(from_us(us));
      }
    }
    EXPECT_EQ(own.cost().total(), shared.cost().total());
    for (std::size_t i = 0; i < kK; ++i)
      for (std::size_t k = 0; k < kK; ++k) EXPECT_EQ(own.covariance()(i, k), shared.covariance()(i, k));
  }
}

TEST(AffineProbe, RecoversAnAffineMapFromItsValues) {
  Matrix<double, 2, 3> a;
  a(0, 0) = 1.5;
  a(0, 2) = -2;
  a(1, 1) = 0.25;
  a(1, 2) = 3;
  const Vector<double, 2> b({0.5, -1});
  const auto f = [&](const Vector<double, 3>& w) { return Vector<double, 2>(a * w + b); };
  Matrix<double, 2, 3> jac;
  Vector<double, 2> off;
  probe_affine<3, 2>(f, Vector<double, 3>({0.3, -7, 2}), 1.0, jac, off);
  for (std::size_t i = 0; i < 2; ++i) {
    for (std::size_t j = 0; j < 3; ++j) EXPECT_NEAR(jac(i, j), a(i, j), 1e-14);
    EXPECT_NEAR(off[i], b[i], 1e-13);
  }
}

}  // namespace
}  // namespace oneshot::engine
