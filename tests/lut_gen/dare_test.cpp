/// @file dare_test.cpp
/// @brief The ordered-QZ DARE against Eigen oracles for n = 3, 6, 12: the residual
///        evaluated independently in long double, a long-double doubling solution, and the
///        closed-loop spectral radius from Eigen's EigenSolver (support/eigen_reference); failures are reported, not
///        returned as solutions.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <random>

#include "oneshot/design/dare.hpp"
#include "oneshot/design/dense_ops.hpp"
#include "oneshot/design/plant_description.hpp"
#include "oneshot/design/sampled_model.hpp"
#include "support/eigen_reference.hpp"

namespace oneshot::design {
namespace {

using test::MatX;
/// Relative residual of X = AᵀXA − AᵀXB(R + BᵀXB)⁻¹BᵀXA + Q, evaluated in long double.
double residual_long(const DenseMatrix& a, const DenseMatrix& b, const DenseMatrix& q, const DenseMatrix& r,
                     const DenseMatrix& x) {
  return test::dare_residual_long(test::to_eigen(a), test::to_eigen(b), test::to_eigen(q), test::to_eigen(r),
                                  MatX::Zero(static_cast<Eigen::Index>(b.rows), static_cast<Eigen::Index>(b.cols)),
                                  test::to_eigen(x));
}

DenseMatrix random_matrix(std::mt19937_64& rng, std::size_t r, std::size_t c, double scale) {
  std::normal_distribution<double> nd(0.0, scale);
  DenseMatrix m = DenseMatrix::zeros(r, c);
  for (double& v : m.values) v = nd(rng);
  return m;
}

double closed_loop_radius_eigen(const DenseMatrix& a, const DenseMatrix& b, const DenseMatrix& r, const DenseMatrix& x) {
  const MatX al = test::to_eigen(a), bl = test::to_eigen(b), xl = test::to_eigen(x);
  const MatX k = (test::to_eigen(r) + bl.transpose() * xl * bl).inverse() * bl.transpose() * xl * al;
  return test::spectral_radius(al - bl * k);
}

/// Random plant with an unstable mode and poles spread over (0.2, 1.3); controllable.
void random_case(std::size_t n, std::size_t m, std::uint64_t seed, DenseMatrix& a, DenseMatrix& b, DenseMatrix& q,
                 DenseMatrix& r) {
  std::mt19937_64 rng(seed);
  a = random_matrix(rng, n, n, 1.0 / std::sqrt(static_cast<double>(n)));
  b = random_matrix(rng, n, m, 1.0);
  const DenseMatrix l = random_matrix(rng, n, n, 1.0);
  q = l * transpose(l) * 0.1;
  symmetrize(q);
  r = identity(m);
}

class DareAgainstEigen : public ::testing::TestWithParam<std::size_t> {};

TEST_P(DareAgainstEigen, ResidualRadiusAndSolutionMatchTheOracles) {
  const std::size_t n = GetParam();
  for (std::uint64_t seed = 1; seed <= 5; ++seed) {
    DenseMatrix a, b, q, r;
    random_case(n, 2, seed * 7919 + n, a, b, q, r);
    const DareSolution sol = solve_dare(a, b, q, r);
    ASSERT_EQ(sol.status, DareStatus::kOk) << "n = " << n << " seed " << seed;
    // Measured ≤ 1.1e−15 for n = 3 … 12 (15 cases); asserted 1e−14.
    EXPECT_LT(residual_long(a, b, q, r, sol.x), 1e-14) << n;
    EXPECT_LT(sol.residual, 1e-14) << n;
    const MatX oracle = test::dare_doubling_long(test::to_eigen(a), test::to_eigen(b), test::to_eigen(q), test::to_eigen(r));
    // Measured ≤ 3.9e−15; asserted 2e−14.
    EXPECT_LT(test::relative_error(test::to_eigen(sol.x), oracle), 2e-14) << n;
    const double rho = closed_loop_radius_eigen(a, b, r, sol.x);
    EXPECT_LT(rho, 1.0);
    EXPECT_NEAR(sol.closed_loop_radius, rho, 2e-14) << n;  // measured ≤ 2.9e−15
  }
}

INSTANTIATE_TEST_SUITE_P(Sizes, DareAgainstEigen, ::testing::Values(3U, 6U, 12U));

TEST(Dare, CrossTermMatchesTheTransformedProblem) {
  DenseMatrix a, b, q, r;
  random_case(6, 2, 42, a, b, q, r);
  std::mt19937_64 rng(43);
  const DenseMatrix s = random_matrix(rng, 6, 2, 0.05);
  const DareSolution with_s = solve_dare(a, b, q + identity(6), r, s);
  ASSERT_EQ(with_s.status, DareStatus::kOk);
  // Ã = A − B R⁻¹ Sᵀ, Q̃ = Q − S R⁻¹ Sᵀ (R = I) gives the same X without a cross term.
  const DareSolution plain = solve_dare(a - b * transpose(s), b, q + identity(6) - s * transpose(s), r);
  ASSERT_EQ(plain.status, DareStatus::kOk);
  EXPECT_LT(test::relative_error(test::to_eigen(with_s.x), test::to_eigen(plain.x)), 2e-15);  // measured 3.2e−16
}

TEST(Dare, BadlyScaledKalmanProblemOfTheHddPlantMatchesLongDouble) {
  // The 12-state HDD Kalman problem: Q ~ 1e−15 only on the disturbance states, CᵀR⁻¹C ~ 4e6,
  // a coupling of 1e5 and an estimator pole within 1e−6 of the unit circle.
  const PlantDescription p = load_plant_file(std::string(ONESHOT_PLANTS_DIR) + "/hdd_numre.json");
  const SampledModel s = sample_plant(p);
  const DenseMatrix at = transpose(s.phi);
  const DenseMatrix ct = transpose(p.c);
  const DareSolution sol = solve_dare(at, ct, s.qd, p.measurement_covariance);
  ASSERT_EQ(sol.status, DareStatus::kOk) << to_string(sol.status);
  const MatX oracle =
      test::dare_doubling_long(test::to_eigen(at), test::to_eigen(ct), test::to_eigen(s.qd), test::to_eigen(p.measurement_covariance));
  // Measured 8.5e−15 (without the state balancing: 9e−6, P(x_d1) < 0 and an unstable
  // estimator); asserted 5e−14.
  EXPECT_LT(test::relative_error(test::to_eigen(sol.x), oracle), 5e-14);
  // The smallest diagonal entry (~4e−22, 19 decades below the largest) keeps its sign and
  // digits (measured 1.0e−10 relative).
  EXPECT_NEAR(sol.x(10, 10), oracle(10, 10), 1e-9 * oracle(10, 10));
  EXPECT_LT(sol.closed_loop_radius, 1.0);
}

TEST(Dare, UncontrollableMarginalModeHasNoStabilisingSolution) {
  // x2 is a pure integrator (λ = 1) that the input cannot reach and the cost weights.
  const DenseMatrix a{2, 2, {0.5, 0.0, 0.0, 1.0}};
  const DenseMatrix b{2, 1, {1.0, 0.0}};
  const DareSolution sol = solve_dare(a, b, identity(2), identity(1));
  EXPECT_NE(sol.status, DareStatus::kOk);
  EXPECT_NE(sol.status, DareStatus::kInaccurate);
}

TEST(Dare, UncontrollableUnstableModeIsNotReturnedAsStabilising) {
  const DenseMatrix a{2, 2, {0.5, 0.0, 0.0, 1.5}};
  const DenseMatrix b{2, 1, {1.0, 0.0}};
  const DareSolution sol = solve_dare(a, b, identity(2), identity(1));
  // The stable deflating subspace holds 1/1.5 with no x component: a singular basis.
  EXPECT_TRUE(sol.status == DareStatus::kNoStabilizing || sol.status == DareStatus::kSingularBasis)
      << to_string(sol.status);
}

TEST(Dare, SingularInputWeightIsReported) {
  DenseMatrix a, b, q, r;
  random_case(3, 2, 5, a, b, q, r);
  EXPECT_EQ(solve_dare(a, b, q, DenseMatrix::zeros(2, 2)).status, DareStatus::kSingularWeight);
}

}  // namespace
}  // namespace oneshot::design
