/// @file spectrum_test.cpp
/// @brief Spectral radius against Eigen's EigenSolver (n = 3, 6, 12, clustered poles near 1),
///        PBH stabilizability / detectability on constructed cases, transmission zeros.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <random>

#include "oneshot/design/dense_ops.hpp"
#include "oneshot/design/spectrum.hpp"
#include "support/eigen_reference.hpp"

namespace oneshot::design {
namespace {

using test::MatX;

/// V diag-block(poles) V⁻¹ with a random well-conditioned V: known eigenvalues.
DenseMatrix with_poles(const std::vector<double>& radii, double angle, std::uint64_t seed) {
  const std::size_t n = radii.size();
  DenseMatrix blocks = DenseMatrix::zeros(n, n);
  for (std::size_t i = 0; i < n; ++i) {
    if (i + 1 < n && angle != 0 && i % 2 == 0) {  // complex pair r e^{±iθ}
      blocks(i, i) = blocks(i + 1, i + 1) = radii[i] * std::cos(angle);
      blocks(i, i + 1) = radii[i] * std::sin(angle);
      blocks(i + 1, i) = -radii[i] * std::sin(angle);
      ++i;
    } else {
      blocks(i, i) = radii[i];
    }
  }
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-0.3, 0.3);
  DenseMatrix v = identity(n);
  for (double& x : v.values) x += u(rng);
  const SolveResult vinv = solve(v, identity(n));
  return v * blocks * vinv.x;
}

double eigen_radius(const DenseMatrix& a) {
  return test::spectral_radius(test::to_eigen(a));
}

class SpectralRadius : public ::testing::TestWithParam<std::size_t> {};

TEST_P(SpectralRadius, MatchesEigenWithPolesClusteredNearOne) {
  const std::size_t n = GetParam();
  std::vector<double> radii(n);
  for (std::size_t i = 0; i < n; ++i) radii[i] = 0.999 - 1e-4 * static_cast<double>(i);  // the T = 20 µs regime
  for (double angle : {0.0, 0.01}) {
    const DenseMatrix a = with_poles(radii, angle, 11 + n);
    // Measured ≤ 3.3e−15 against Eigen, ≤ 1.7e−15 against the constructed 0.999; asserted
    // 2e−14. (The characteristic polynomial of the replaced code loses these digits for
    // clustered poles from n ≈ 4 on.)
    EXPECT_NEAR(spectral_radius(a), eigen_radius(a), 2e-14) << n;
    EXPECT_NEAR(spectral_radius(a), 0.999, 2e-14) << n;
  }
}

INSTANTIATE_TEST_SUITE_P(Sizes, SpectralRadius, ::testing::Values(3U, 6U, 12U));

TEST(Pbh, UncontrollableUnstableModeFailsStabilizability) {
  const DenseMatrix a{3, 3, {0.5, 1.0, 0.0, 0.0, 0.8, 0.0, 0.0, 0.0, 1.2}};
  const DenseMatrix b{3, 1, {0.0, 1.0, 0.0}};
  const ModeCheck c = stabilizable(a, b);
  ASSERT_FALSE(c.ok);
  ASSERT_EQ(c.failing.size(), 1U);
  EXPECT_NEAR(c.failing[0].real(), 1.2, 1e-12);
  EXPECT_FALSE(controllable(a, b).ok);
}

TEST(Pbh, UncontrollableStableModeIsStabilizableButNotControllable) {
  const DenseMatrix a{3, 3, {1.1, 1.0, 0.0, 0.0, 0.8, 0.0, 0.0, 0.0, 0.3}};
  const DenseMatrix b{3, 1, {0.0, 1.0, 0.0}};
  EXPECT_TRUE(stabilizable(a, b).ok);
  EXPECT_FALSE(controllable(a, b).ok);
}

TEST(Pbh, UnobservableMarginalModeFailsDetectability) {
  // The reference board read on v2 only: Φ = [[1, −1.19], [0, 1]], C = [0, 1].
  const DenseMatrix phi{2, 2, {1.0, -1.19, 0.0, 1.0}};
  EXPECT_FALSE(detectable(phi, DenseMatrix{1, 2, {0.0, 1.0}}).ok);
  EXPECT_TRUE(detectable(phi, DenseMatrix{1, 2, {1.0, 0.0}}).ok);
  EXPECT_TRUE(observable(phi, DenseMatrix{1, 2, {1.0, 0.0}}).ok);
}

TEST(Pbh, StabilizabilityIsInvariantUnderASimilarity) {
  // The same uncontrollable unstable mode hidden by a dense change of coordinates.
  const DenseMatrix a0{3, 3, {0.5, 1.0, 0.0, 0.0, 0.8, 0.0, 0.0, 0.0, 1.2}};
  const DenseMatrix b0{3, 1, {0.0, 1.0, 0.0}};
  const DenseMatrix t{3, 3, {1.0, 0.3, -0.2, 0.1, 1.0, 0.4, -0.3, 0.2, 1.0}};
  const SolveResult ti = solve(t, identity(3));
  EXPECT_FALSE(stabilizable(ti.x * a0 * t, ti.x * b0).ok);
  EXPECT_TRUE(stabilizable(ti.x * a0 * t, ti.x * DenseMatrix{3, 1, {0.0, 1.0, 1.0}}).ok);
}

TEST(Pbh, BadlyScaledCouplingStaysObservable) {
  // A state seen only through a coupling of 1e5 and a slow chain: observable, however scaled.
  const DenseMatrix a{3, 3, {0.99, 0.0, 1e5, 1e-5, 0.98, 0.0, 0.0, 0.0, 0.97}};
  const DenseMatrix c{1, 3, {0.0, 1.0, 0.0}};
  EXPECT_TRUE(observable(a, c).ok) << observable(a, c).describe();
}

TEST(TransmissionZeros, DiscreteSecondOrderExample) {
  // H(z) = (z − 0.5)/((z − 0.2)(z − 0.9)): controllable canonical form.
  const DenseMatrix a{2, 2, {1.1, -0.18, 1.0, 0.0}};
  const DenseMatrix b{2, 1, {1.0, 0.0}};
  const DenseMatrix c{1, 2, {1.0, -0.5}};
  const auto z = transmission_zeros(a, b, c, DenseMatrix{1, 1, {0.0}});
  ASSERT_EQ(z.size(), 1U);
  EXPECT_NEAR(z[0].real(), 0.5, 1e-12);
  EXPECT_NEAR(z[0].imag(), 0.0, 1e-12);
}

}  // namespace
}  // namespace oneshot::design
