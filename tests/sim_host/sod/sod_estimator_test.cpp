/// @file sod_estimator_test.cpp
/// @brief The §4 estimator: two scalar corrections against the core's joint correction,
///        and a recorded run against an Eigen oracle of the brief's joint equations.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <cstdio>
#include <random>

#include "oneshot/kalman_correction.hpp"
#include "oneshot/node/held_measurement_estimator.hpp"
#include "oneshot/number_format.hpp"
#include "oneshot/plant_structure.hpp"
#include "support/eigen_reference.hpp"
#include "sod_model.hpp"
#include "sod_sim.hpp"

namespace {

using oneshot::Matrix;
using oneshot::Vector;
using Est = oneshot::node::HeldMeasurementEstimator<double, 2, 1, 2>;

TEST(SodEstimator, TwoScalarCorrectionsEqualTheJointOne) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  double worst = 0;
  for (int trial = 0; trial < 2000; ++trial) {
    Matrix<double, 2, 2> l, p, c, r;
    l(0, 0) = 0.1 + std::abs(u(rng));
    l(1, 0) = u(rng);
    l(1, 1) = 0.1 + std::abs(u(rng));
    for (std::size_t i = 0; i < 2; ++i)
      for (std::size_t j = 0; j < 2; ++j)
        for (std::size_t k = 0; k < 2; ++k) p(i, j) += l(i, k) * l(j, k);
    for (std::size_t i = 0; i < 2; ++i)
      for (std::size_t j = 0; j < 2; ++j) c(i, j) = trial % 2 == 0 ? (i == j ? 1.0 : 0.0) : u(rng) + (i == j ? 2.0 : 0.0);
    r(0, 0) = 0.01 + std::abs(u(rng));
    r(1, 1) = 0.01 + 3 * std::abs(u(rng));
    Vector<double, 2> x, z;
    x[0] = u(rng);
    x[1] = u(rng);
    z[0] = u(rng);
    z[1] = u(rng);
    Est est(Matrix<double, 2, 2>{}, Matrix<double, 2, 1>{}, Matrix<double, 2, 2>{}, c);
    est.reset(x, p);
    ASSERT_EQ(est.correct(0, z[0], r(0, 0)), oneshot::Status::kOk);
    ASSERT_EQ(est.correct(1, z[1], r(1, 1)), oneshot::Status::kOk);
    Vector<double, 2> xj = x;
    Matrix<double, 2, 2> pj = p;
    Matrix<double, 2, 2> k;
    using Fmt = oneshot::UniformFormat<double>;
    ASSERT_EQ((oneshot::correct<Fmt, oneshot::DenseStructure<2, 1, 2>, oneshot::CovarianceUpdate::kSymmetric>(xj, pj, z, c, r, k)),
              oneshot::Status::kOk);
    for (std::size_t i = 0; i < 2; ++i) {
      worst = std::max(worst, std::abs(est.estimate()[i] - xj[i]) / (1 + std::abs(xj[i])));
      for (std::size_t j = 0; j < 2; ++j) worst = std::max(worst, std::abs(est.covariance()(i, j) - pj(i, j)) / (1 + std::abs(pj(i, j))));
    }
  }
  std::printf("sequential vs joint correction: largest relative difference %.3g\n", worst);
  EXPECT_LT(worst, 1e-12) << "largest relative difference " << worst;
}

TEST(SodEstimator, RecordedRunMatchesEigenOracle) {
  const oneshot::sod::SodModel m = oneshot::sod::load_sod_model(oneshot::sod::default_sod_plant_path());
  oneshot::sod::RunConfig cfg;
  cfg.sender = oneshot::sod::SenderKind::kModifiedSod;
  cfg.n_t[0] = 80;
  cfg.n_t[1] = 120;
  cfg.loss = 0.2;
  cfg.steps = 3000;
  oneshot::sod::RunTrace tr;
  oneshot::sod::simulate_run(m, cfg, 11, &tr);
  const Eigen::MatrixXd a = oneshot::test::to_eigen(m.a_d), q = oneshot::test::to_eigen(m.q_d),
                        c = oneshot::test::to_eigen(m.c), b = oneshot::test::to_eigen(m.b_d);
  Eigen::VectorXd x = Eigen::VectorXd::Zero(2);
  Eigen::MatrixXd p = cfg.p0 * Eigen::MatrixXd::Identity(2, 2);
  double worst_x = 0, worst_p = 0;
  std::size_t held = 0, detected = 0;
  for (std::size_t k = 0; k < tr.t_s.size(); ++k) {
    if (k > 0) {
      x = a * x + b.col(0) * cfg.amplitude;
      p = a * p * a.transpose() + q;
    }
    // Joint correction with the present rows: K = P⁻Cᵀ(C P⁻Cᵀ + R̄)⁻¹ (a full inverse).
    std::vector<std::size_t> rows;
    for (std::size_t i = 0; i < 2; ++i)
      if (!std::isnan(tr.z[i][k])) rows.push_back(i);
    if (!rows.empty()) {
      const auto nr = static_cast<Eigen::Index>(rows.size());
      Eigen::MatrixXd cr(nr, 2), rb = Eigen::MatrixXd::Zero(nr, nr);
      Eigen::VectorXd z(nr);
      for (Eigen::Index r = 0; r < nr; ++r) {
        const std::size_t i = rows[static_cast<std::size_t>(r)];
        cr.row(r) = c.row(static_cast<Eigen::Index>(i));
        rb(r, r) = tr.r_bar[i][k];
        z(r) = tr.z[i][k];
        if (tr.arrived[i][k] == 0) ++held;
        if (tr.dropouts[i][k] > 0) ++detected;
      }
      const Eigen::MatrixXd kk = p * cr.transpose() * (cr * p * cr.transpose() + rb).inverse();
      x = x + kk * (z - cr * x);
      p = (Eigen::MatrixXd::Identity(2, 2) - kk * cr) * p;
      p = (0.5 * (p + p.transpose())).eval();
    }
    for (std::size_t i = 0; i < 2; ++i) {
      ASSERT_LE(tr.dropouts[i][k], tr.true_lost_run[i][k]) << "k " << k;  // d is a lower bound
      const auto e = static_cast<Eigen::Index>(i);
      worst_x = std::max(worst_x, std::abs(x(e) - tr.x_hat[i][k]) / (1 + std::abs(x(e))));
      worst_p = std::max(worst_p, std::abs(p(e, e) - tr.p[i][k]) / p(e, e));
    }
  }
  EXPECT_GT(held, 1000u);     // the sequence exercises held values …
  EXPECT_GT(detected, 10u);   // … and detected dropouts
  std::printf("run vs Eigen oracle: x %.3g, P %.3g (relative)\n", worst_x, worst_p);
  EXPECT_LT(worst_x, 1e-13) << worst_x;  // measured 2.7e-15
  EXPECT_LT(worst_p, 1e-13) << worst_p;  // measured 1.5e-15
}

}  // namespace
