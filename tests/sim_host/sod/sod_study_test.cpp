/// @file sod_study_test.cpp
/// @brief The study's run and design: common random numbers across ξ, the δy = 0 / ξ = 0
///        limit against the periodic filter's steady state, a noise-free invariant, NEES of
///        the periodic filter, δt*·ξ constant, unbounded δt reported.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <cstdio>

#include "oneshot/node/send_cause.hpp"
#include "support/eigen_reference.hpp"
#include "sod_design.hpp"
#include "sod_model.hpp"
#include "sod_sim.hpp"
#include "study_model.hpp"

namespace {

using namespace oneshot::sod;

/// Steady-state prior and posterior of the periodic filter by iterating the Riccati map (Eigen).
std::pair<Eigen::MatrixXd, Eigen::MatrixXd> riccati_fixed_point(const Eigen::MatrixXd& rbar) {
  const Eigen::MatrixXd a = oneshot::test::to_eigen(study_model().a_d), q = oneshot::test::to_eigen(study_model().q_d),
                        c = oneshot::test::to_eigen(study_model().c);
  Eigen::MatrixXd p = Eigen::MatrixXd::Identity(2, 2);
  Eigen::MatrixXd post = p;
  for (int it = 0; it < 200000; ++it) {
    const Eigen::MatrixXd k = p * c.transpose() * (c * p * c.transpose() + rbar).inverse();
    post = (Eigen::MatrixXd::Identity(2, 2) - k * c) * p;
    const Eigen::MatrixXd next = a * post * a.transpose() + q;
    if ((next - p).norm() < 1e-17) break;
    p = next;
  }
  return {p, post};
}

TEST(SodStudy, PlainSodSendsTheSamePacketsAtEveryLossRate) {
  for (std::uint64_t seed : {1u, 2u}) {
    RunConfig cfg;
    cfg.steps = 2000;
    double sends[2] = {-1, -1}, lost_prev[2] = {0, 0};
    for (double xi : {0.0, 0.05, 0.1, 0.2}) {
      cfg.loss = xi;
      const RunResult r = simulate_run(study_model(), cfg, seed);
      for (int i = 0; i < 2; ++i) {
        if (sends[i] < 0) sends[i] = r.sends[i];
        EXPECT_EQ(r.sends[i], sends[i]) << "seed " << seed << " xi " << xi;
        EXPECT_GE(r.lost[i], lost_prev[i]);  // one uniform per packet: losses at ξ ⊂ losses at ξ' > ξ
        lost_prev[i] = r.lost[i];
        EXPECT_EQ(r.time_sends[i], 0);
      }
    }
    EXPECT_GT(lost_prev[0] + lost_prev[1], 0);
  }
}

TEST(SodStudy, DeltaYZeroLosslessIsThePeriodicFilterAtSteadyState) {
  RunConfig sod;
  sod.delta_y[0] = sod.delta_y[1] = 0;
  sod.loss = 0;
  sod.steps = 5000;
  RunConfig periodic = sod;
  periodic.sender = SenderKind::kPeriodic;
  periodic.filter = FilterKind::kPredictOnly;
  Eigen::MatrixXd r = Eigen::MatrixXd::Zero(2, 2);
  r(0, 0) = study_model().r_diag[0];
  r(1, 1) = study_model().r_diag[1];
  const Eigen::MatrixXd post = riccati_fixed_point(r).second;
  const int seeds = 20;
  double e[2] = {0, 0};
  for (int s = 1; s <= seeds; ++s) {
    RunTrace tr;
    const RunResult a = simulate_run(study_model(), sod, static_cast<std::uint64_t>(s), &tr);
    const RunResult b = simulate_run(study_model(), periodic, static_cast<std::uint64_t>(s));
    for (std::size_t i = 0; i < 2; ++i) {
      const auto ei = static_cast<Eigen::Index>(i);
      EXPECT_EQ(a.sends[i], static_cast<double>(sod.steps + 1));  // δy = 0: every sample is sent
      EXPECT_EQ(a.e[i], b.e[i]);                                   // … and the filter is the periodic one
      EXPECT_NEAR(tr.p[i].back(), post(ei, ei), 1e-12 * post(ei, ei));  // P reaches the steady state
      e[i] += a.e[i] / seeds;
    }
  }
  // The mean squared error matches the steady-state posterior variance (Monte Carlo:
  // 20 × 5000 correlated steps; measured deviation ≈ 1 %).
  for (Eigen::Index i = 0; i < 2; ++i) {
    std::printf("node %ld: mean e = %.6g, steady-state posterior P_ii = %.6g (relative deviation %.3g)\n", i + 1, e[i],
                post(i, i), std::abs(e[i] - post(i, i)) / post(i, i));
    EXPECT_NEAR(e[i], post(i, i), 0.05 * post(i, i)) << "node " << i + 1;
  }
}

TEST(SodStudy, PeriodicFilterNeesIsTwo) {
  RunConfig c;
  c.sender = SenderKind::kPeriodic;
  c.filter = FilterKind::kPredictOnly;
  c.steps = 5000;
  c.loss = 0.2;
  double nees = 0;
  for (int s = 1; s <= 10; ++s) nees += simulate_run(study_model(), c, static_cast<std::uint64_t>(s)).nees / 10;
  std::printf("periodic filter at xi = 0.2: mean NEES over 10 runs = %.4f\n", nees);
  EXPECT_NEAR(nees, 2.0, 0.1);
}

TEST(SodStudy, NoiseFreeInvariants) {
  // Without noise, a lossless link and x̂(0) = x(0): the plant follows x⁺ = A_d x + B_d u
  // exactly, a held value is never further than δy from the truth, no dropout is ever
  // detected, and modified SOD is never silent for n_t samples.
  for (SenderKind sender : {SenderKind::kSod, SenderKind::kModifiedSod}) {
    RunConfig c;
    c.sender = sender;
    c.noise = false;
    c.loss = 0;
    c.n_t[0] = c.n_t[1] = 300;
    c.steps = 5000;
    RunTrace tr;
    simulate_run(study_model(), c, 5, &tr);
    double x[2] = {0, 0};
    std::size_t since[2] = {0, 0}, held = 0;
    for (std::size_t k = 0; k < tr.t_s.size(); ++k) {
      if (k > 0) {
        const double x0 = study_model().a_d(0, 0) * x[0] + study_model().a_d(0, 1) * x[1] + study_model().b_d(0, 0) * c.amplitude;
        const double x1 = study_model().a_d(1, 0) * x[0] + study_model().a_d(1, 1) * x[1] + study_model().b_d(1, 0) * c.amplitude;
        x[0] = x0;
        x[1] = x1;
      }
      for (std::size_t i = 0; i < 2; ++i) {
        ASSERT_NEAR(tr.x[i][k], x[i], 1e-9 * (1 + std::abs(x[i])));
        ASSERT_EQ(tr.y[i][k], tr.x[i][k]);
        ASSERT_EQ(tr.dropouts[i][k], 0u);
        if (tr.arrived[i][k] == 0) {
          ++held;
          ASSERT_LE(std::abs(tr.x[i][k] - tr.z[i][k]), c.delta_y[i]) << "k " << k;
          ++since[i];
          if (sender == SenderKind::kModifiedSod) {
            ASSERT_LT(since[i], c.n_t[i]);
          }
        } else {
          since[i] = 0;
        }
      }
    }
    EXPECT_GT(held, 5000u);
  }
}

TEST(SodDesign, DeltaTTimesLossIsConstantAndTheOptimumIsChecked) {
  DesignInputs in;
  in.delta_y[0] = in.delta_y[1] = 0.2;  // both constraints bind here (at δy = 0.5 node 2 is unbounded)
  in.mean_gap_s[0] = 1.3;
  in.mean_gap_s[1] = 0.7;
  double dtxi[2] = {0, 0};
  DeltaTDesign d;
  for (double xi : {0.05, 0.1, 0.15, 0.2}) {
    in.loss[0] = in.loss[1] = xi;
    d = design_delta_t(study_model(), in);
    EXPECT_TRUE(d.grid_check_passed) << d.packets_per_s << " vs grid " << d.grid_best_packets_per_s;
    EXPECT_FALSE(d.active.empty());
    for (std::size_t i = 0; i < 2; ++i) {
      ASSERT_TRUE(d.node[i].bounded) << d.node[i].reason;
      EXPECT_LE(d.p_diag[i], in.mu * d.p0_diag[i] * (1 + 1e-9));
      if (dtxi[i] == 0) dtxi[i] = d.node[i].delta_t_times_loss;
      EXPECT_NEAR(d.node[i].delta_t_times_loss, dtxi[i], 1e-6 * dtxi[i]);
    }
  }
  // P0 is the prior Riccati fixed point with R̄ = R + δy²/3.
  Eigen::MatrixXd rb = Eigen::MatrixXd::Zero(2, 2);
  for (std::size_t i = 0; i < 2; ++i) {
    const auto e = static_cast<Eigen::Index>(i);
    rb(e, e) = study_model().r_diag[i] + in.delta_y[i] * in.delta_y[i] / 3;
  }
  const Eigen::MatrixXd prior = riccati_fixed_point(rb).first;
  for (std::size_t i = 0; i < 2; ++i) {
    const auto e = static_cast<Eigen::Index>(i);
    EXPECT_NEAR(d.p0_diag[i], prior(e, e), 1e-9 * prior(e, e));
  }
}

TEST(SodDesign, UnboundedDeltaTIsReportedWithItsReason) {
  DesignInputs in;
  in.mean_gap_s[0] = in.mean_gap_s[1] = 1;
  in.mu = 1e6;  // no measurement at all still meets the bound
  const DeltaTDesign d = design_delta_t(study_model(), in);
  for (std::size_t i = 0; i < 2; ++i) {
    EXPECT_FALSE(d.node[i].bounded);
    EXPECT_NE(d.node[i].reason.find("rule (2b) off"), std::string::npos);
  }
  EXPECT_TRUE(d.active.empty());
  in.loss[0] = in.loss[1] = 0;
  in.mu = 5;
  const DeltaTDesign z = design_delta_t(study_model(), in);
  EXPECT_FALSE(z.node[0].bounded);
  EXPECT_NE(z.node[0].reason.find("loss rate 0"), std::string::npos);
  in.mu = 1;
  EXPECT_THROW(design_delta_t(study_model(), in), std::invalid_argument);
}

}  // namespace
