/// @file controller_synthesis_test.cpp
/// @brief The design step against independent Eigen computations: quadrature-sampled
///        cost, plain Riccati iteration for L and K, eigenvalues, and closed forms.
#include <gtest/gtest.h>

#include <cmath>

#include "oneshot/design/controller_synthesis.hpp"
#include "support/eigen_reference.hpp"
#include "support/test_plants.hpp"
#include "support/expect_error.hpp"

namespace oneshot::design {
namespace {

using test::MatX;

struct Reference {
  MatX q1, q12, q2, l, k;
};

/// Sampled cost by Gauss–Legendre quadrature and L, K by iterating the Riccati
/// difference equations to convergence (no doubling, no Van Loan).
Reference independent_design(const PlantDescription& p, const DesignResult& d) {
  const MatX a = test::to_eigen(p.a);
  const MatX b = test::to_eigen(p.b);
  const MatX c = test::to_eigen(p.c);
  const Eigen::Index n = a.rows();
  const Eigen::Index m = b.cols();
  const double h = p.period_us * 1e-6;
  MatX f = MatX::Zero(n + m, n + m);
  f.topLeftCorner(n, n) = a;
  f.topRightCorner(n, m) = b;
  MatX w = MatX::Zero(n + m, n + m);
  w.topLeftCorner(n, n) = test::to_eigen(p.q1c);
  w.bottomRightCorner(m, m) = test::to_eigen(p.q2c);
  // ∫₀ʰ e^{Fᵀs} W e^{Fs} ds = qd_by_quadrature(Fᵀ, W, h).
  const MatX qs = test::qd_by_quadrature(f.transpose(), w, h, 400);
  Reference r;
  r.q1 = qs.topLeftCorner(n, n);
  r.q12 = qs.topRightCorner(n, m);
  r.q2 = qs.bottomRightCorner(m, m);
  const MatX fe = test::expm(f * h);
  const MatX phi = fe.topLeftCorner(n, n);
  const MatX gamma = fe.topRightCorner(n, m);
  MatX s = r.q1;
  for (int it = 0; it < 20000; ++it) {
    const MatX gain = (r.q2 + gamma.transpose() * s * gamma).inverse() * (gamma.transpose() * s * phi + r.q12.transpose());
    s = r.q1 + phi.transpose() * s * phi - (phi.transpose() * s * gamma + r.q12) * gain;
    s = 0.5 * (s + s.transpose()).eval();
  }
  r.l = (r.q2 + gamma.transpose() * s * gamma).inverse() * (gamma.transpose() * s * phi + r.q12.transpose());
  const MatX q = test::to_eigen(d.qd_h);
  const MatX rr = test::to_eigen(p.measurement_covariance);
  MatX pp = q;
  for (int it = 0; it < 20000; ++it) {
    const MatX gain = phi * pp * c.transpose() * (c * pp * c.transpose() + rr).inverse();
    pp = phi * pp * phi.transpose() + q - gain * c * pp * phi.transpose();
    pp = 0.5 * (pp + pp.transpose()).eval();
  }
  r.k = pp * c.transpose() * (c * pp * c.transpose() + rr).inverse();
  return r;
}

void check_against_independent(const PlantDescription& p) {
  const DesignResult d = synthesize(p);
  const Reference r = independent_design(p, d);
  EXPECT_LT(test::relative_error(test::to_eigen(d.q1), r.q1), 1e-10) << p.name;
  EXPECT_LT(test::relative_error(test::to_eigen(d.q12), r.q12), 1e-10) << p.name;
  EXPECT_LT(test::relative_error(test::to_eigen(d.q2), r.q2), 1e-10) << p.name;
  EXPECT_LT(test::relative_error(test::to_eigen(d.l), r.l), 1e-8) << p.name;
  EXPECT_LT(test::relative_error(test::to_eigen(d.kalman_gain), r.k), 1e-8) << p.name;
  // Closed-loop spectral radius against Eigen's eigenvalues.
  const MatX cl = test::to_eigen(d.phi_h) - test::to_eigen(d.gamma_h) * test::to_eigen(d.l);
  const double rho = test::spectral_radius(cl);
  EXPECT_NEAR(d.closed_loop_radius, rho, 1e-8) << p.name;
  EXPECT_LT(rho, 1.0);
}

TEST(ControllerSynthesis, ReferenceMatchesIndependentComputation) { check_against_independent(reference_plant()); }
TEST(ControllerSynthesis, DampedOscillatorMatches) { check_against_independent(test::damped_oscillator()); }
TEST(ControllerSynthesis, UnstablePoleMatches) { check_against_independent(test::unstable_plant()); }
TEST(ControllerSynthesis, ThreeStateMatches) { check_against_independent(test::three_state_plant()); }

TEST(ControllerSynthesis, ReferenceClosedForms) {
  const DesignResult d = synthesize(reference_plant());
  // Double integrator: Φ(h) = [[1, −ah], [0, 1]], Γ(h) = [a²h²/2, −ah], a = 23.8, h = 0.05.
  EXPECT_DOUBLE_EQ(d.phi_h(0, 0), 1.0);
  EXPECT_NEAR(d.phi_h(0, 1), -1.19, 1e-15);
  EXPECT_DOUBLE_EQ(d.phi_h(1, 0), 0.0);
  EXPECT_NEAR(d.gamma_h(0, 0), 23.8 * 23.8 * 0.05 * 0.05 / 2, 1e-15);
  EXPECT_NEAR(d.gamma_h(1, 0), -1.19, 1e-15);
  // Q_d(h) with Q_c = q I: [[q(h + a²h³/3), −q a h²/2], [·, q h]], q = 2e-7/h.
  const double q = 2e-7 / 0.05;
  EXPECT_NEAR(d.qd_h(0, 0), q * (0.05 + 23.8 * 23.8 * 0.05 * 0.05 * 0.05 / 3), 1e-20);
  EXPECT_NEAR(d.qd_h(0, 1), -q * 23.8 * 0.05 * 0.05 / 2, 1e-20);
  EXPECT_NEAR(d.qd_h(1, 1), q * 0.05, 1e-20);
  // Feed-forward: A N_x + B N_u = 0, C N_x = 1 → N_x = [1, 0], N_u = 0.
  EXPECT_EQ(d.nx(0, 0), 1.0);
  EXPECT_EQ(d.nx(1, 0), 0.0);
  EXPECT_EQ(d.nu(0, 0), 0.0);
  EXPECT_TRUE(d.tracking);
}

TEST(ControllerSynthesis, DeadbeatObserverIsNilpotent) {
  for (const PlantDescription& p : {reference_plant(), test::damped_oscillator(), test::three_state_plant()}) {
    const DesignResult d = synthesize(p);
    ASSERT_TRUE(d.deadbeat) << p.name;
    const MatX phi = test::to_eigen(d.phi_h);
    const MatX e = (MatX::Identity(phi.rows(), phi.cols()) - test::to_eigen(d.deadbeat_gain) * test::to_eigen(p.c)) * phi;
    MatX power = MatX::Identity(phi.rows(), phi.cols());
    for (Eigen::Index k = 0; k < phi.rows(); ++k) power = power * e;
    EXPECT_LT(power.cwiseAbs().maxCoeff(), 1e-9 * (1 + phi.cwiseAbs().maxCoeff())) << p.name;
  }
}

TEST(ControllerSynthesis, InitialCovarianceDefaultsToTheSteadyStatePrior) {
  const DesignResult d = synthesize(reference_plant());
  EXPECT_EQ(d.p0, d.kalman_prior);
}

TEST(ControllerSynthesis, UnstabilisablePlantIsRefused) {
  // The second state is unstable and not driven by the input.
  const auto p = parse_plant(test::plant_json("[[-1, 0], [0, 2]]", "[[1], [0]]", "[[1, 1]]"), "unstabilisable");
  test::expect_error_naming<DesignError>([&] { synthesize(p); }, {"LQR"});
}

TEST(ControllerSynthesis, UndetectablePlantIsRefused) {
  // The first state is unstable and invisible in the output.
  const auto p = parse_plant(test::plant_json("[[2, 0], [0, -1]]", "[[1], [1]]", "[[0, 1]]"), "undetectable");
  test::expect_error_naming<DesignError>([&] { synthesize(p); }, {"Kalman"});
}

}  // namespace
}  // namespace oneshot::design
