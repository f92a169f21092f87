/// @file zoh_inverse_test.cpp
/// @brief The exact inverse of zero-order-hold sampling (sampled_model.hpp zoh_inverse) against
///        known continuous plants: random stable and unstable (A, B) sampled with the design
///        step's own exponential come back to rounding, an intensity Q_c sampled by Van Loan
///        comes back from its Q_d, and the refusals (a negative real eigenvalue, a singular Φ,
///        a per-step covariance no white noise gives) name the part at fault; a tiny Γ comes back
///        to its own precision and is checked against its own norm (a corrupted one is refused
///        naming Γ), a failed logarithm says whether an eigenvalue near the negative real axis is
///        the cause, and κ₁(Φ) matches its closed form.
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <cstdio>
#include <cstdint>
#include <random>
#include <string>

#include "oneshot/design/dense_ops.hpp"
#include "oneshot/design/spectrum.hpp"
#include "oneshot/design/zoh_inverse.hpp"

namespace oneshot::design {
namespace {

DenseMatrix random_matrix(std::mt19937_64& rng, std::size_t r, std::size_t c) {
  std::normal_distribution<double> g(0.0, 1.0);
  DenseMatrix m = DenseMatrix::zeros(r, c);
  for (double& v : m.values) v = g(rng);
  return m;
}

double rel(const DenseMatrix& got, const DenseMatrix& want) { return norm1(got - want) / norm1(want); }

/// Φ, Γ of (A, B) over h: the augmented exponential, the design step's own (dense_ops expm).
void c2d(const DenseMatrix& a, const DenseMatrix& b, double h, DenseMatrix& phi, DenseMatrix& gamma) {
  const std::size_t n = a.rows;
  const std::size_t m = b.cols;
  DenseMatrix f = DenseMatrix::zeros(n + m, n + m);
  set_block(f, 0, 0, a * h);
  set_block(f, 0, n, b * h);
  const DenseMatrix e = expm(f, "test c2d");
  phi = block(e, 0, 0, n, n);
  gamma = block(e, 0, n, n, m);
}

/// Q_d = ∫₀ʰ e^{As} Q_c e^{Aᵀs} ds by Van Loan (as sample_plant).
DenseMatrix van_loan(const DenseMatrix& a, const DenseMatrix& qc, double h) {
  const std::size_t n = a.rows;
  DenseMatrix vl = DenseMatrix::zeros(2 * n, 2 * n);
  set_block(vl, 0, 0, -a * h);
  set_block(vl, 0, n, qc * h);
  set_block(vl, n, n, transpose(a) * h);
  const DenseMatrix e = expm(vl, "test Van Loan");
  DenseMatrix qd = transpose(block(e, n, n, n, n)) * block(e, 0, n, n, n);
  symmetrize(qd);
  return qd;
}

// (a) Random (A, B), n = 2 … 8, m = 1, 2, half of them unstable, h with max |λ(A)| h in
// [0.05, 2.5] (below π: no aliasing, A is the principal logarithm): c2d then d2c. Measured
// over these 48 plants: A ≤ 5.9e−15, B ≤ 9.9e−16 relative (‖·‖₁), reconstruction ≤ 1.3e−14;
// asserted 3e−14 and 6e−14.
TEST(ZohInverse, RecoversRandomStableAndUnstablePlants) {
  double worst_a = 0;
  double worst_b = 0;
  double worst_fit = 0;
  for (std::uint64_t seed = 1; seed <= 48; ++seed) {
    std::mt19937_64 rng(0x2d2c0000 + seed);
    const std::size_t n = 2 + seed % 7;
    const std::size_t m = 1 + seed % 2;
    DenseMatrix a = random_matrix(rng, n, n);
    // Shift the spectrum: stable (max Re λ < 0) for odd seeds, one unstable mode or more for even.
    double max_re = -1e300;
    for (const auto& l : eigenvalues(a)) max_re = std::fmax(max_re, l.real());
    const double shift = (seed % 2 == 1) ? -(max_re + 0.3) : 0.5 - max_re;
    for (std::size_t i = 0; i < n; ++i) a(i, i) += shift;
    const DenseMatrix b = random_matrix(rng, n, m);
    const double rho = spectral_radius(a);
    const double h = (0.05 + 2.45 * std::uniform_real_distribution<double>(0, 1)(rng)) / rho;
    DenseMatrix phi, gamma;
    c2d(a, b, h, phi, gamma);
    const ZohInverse r = zoh_inverse(phi, gamma, h);
    worst_a = std::fmax(worst_a, rel(r.a, a));
    worst_b = std::fmax(worst_b, rel(r.b, b));
    worst_fit = std::fmax(worst_fit, r.relative_error);
    EXPECT_LT(rel(r.a, a), 3e-14) << "seed " << seed << " n " << n << " h " << h;
    EXPECT_LT(rel(r.b, b), 3e-14) << "seed " << seed;
    EXPECT_LT(r.relative_error, 6e-14) << "seed " << seed;
  }
  std::printf("zoh_inverse: worst relative error A %.3g, B %.3g, reconstruction %.3g\n", worst_a, worst_b, worst_fit);
}

// An integrator (Φ with eigenvalue 1, Φ − I singular) and a lightly damped pair near ωh = 3
// (close to the aliasing limit π): still recovered. Measured 0 and 2.5e−15; asserted 2e−14.
TEST(ZohInverse, RecoversIntegratorsAndFastOscillations) {
  const DenseMatrix a1{2, 2, {0.0, 1.0, 0.0, 0.0}};
  const DenseMatrix b1{2, 1, {0.0, 1.0}};
  const double w = 3.0;
  const DenseMatrix a2{2, 2, {-0.01, w, -w, -0.01}};
  const DenseMatrix b2{2, 1, {0.0, w}};
  for (const auto& [a, b] : {std::pair{a1, b1}, std::pair{a2, b2}}) {
    DenseMatrix phi, gamma;
    c2d(a, b, 1.0, phi, gamma);
    const ZohInverse r = zoh_inverse(phi, gamma, 1.0);
    EXPECT_LT(rel(r.a, a), 2e-14);
    EXPECT_LT(rel(r.b, b), 2e-14);
  }
}

// Q_c (full rank, and rank-deficient as a double integrator's input noise) sampled by Van Loan,
// then recovered from Q_d with the recovered A. Measured ≤ 5.5e−15 relative (Q_d back ≤ 2e−15);
// asserted 3e−14 (1e−14).
TEST(ZohInverse, RecoversTheNoiseIntensityFromItsPerStepCovariance) {
  std::mt19937_64 rng(0x2d2c0a0a);
  for (int k = 0; k < 8; ++k) {
    const std::size_t n = 2 + static_cast<std::size_t>(k % 3);
    DenseMatrix a = random_matrix(rng, n, n);
    const DenseMatrix b = random_matrix(rng, n, 1);
    const double h = 1.0 / spectral_radius(a);
    DenseMatrix qc;
    if (k % 2 == 0) {
      const DenseMatrix g = random_matrix(rng, n, n);
      qc = g * transpose(g);
    } else {
      qc = DenseMatrix::zeros(n, n);
      qc(n - 1, n - 1) = 2.5;
    }
    DenseMatrix phi, gamma;
    c2d(a, b, h, phi, gamma);
    const DenseMatrix qd = van_loan(a, qc, h);
    const ZohInverse r = zoh_inverse(phi, gamma, h, qd);
    EXPECT_LT(rel(r.qc, qc), 3e-14) << k;
    EXPECT_LT(r.noise_relative_error, 1e-14) << k;
  }
}

ZohInverseError::Part refused_part(const DenseMatrix& phi, const DenseMatrix& gamma, const DenseMatrix& qd = {}) {
  try {
    (void)zoh_inverse(phi, gamma, 0.01, qd);
  } catch (const ZohInverseError& e) {
    return e.part();
  }
  ADD_FAILURE() << "not refused";
  return ZohInverseError::Part::kPhi;
}

// (c) Φ with a negative real eigenvalue, a singular Φ, and a Q_d no white noise gives (the
// position's variance 0 over the step while the velocity's is not, for a double integrator).
TEST(ZohInverse, RefusesWhatHasNoUniqueRealLogarithmOrNoNoiseIntensity) {
  const DenseMatrix gamma{2, 1, {0.0, 0.01}};
  EXPECT_EQ(refused_part(DenseMatrix{2, 2, {-0.5, 0.1, 0.0, 0.9}}, gamma), ZohInverseError::Part::kPhi);
  EXPECT_EQ(refused_part(DenseMatrix{2, 2, {1.0, 0.1, 0.0, 0.0}}, gamma), ZohInverseError::Part::kPhi);
  const DenseMatrix phi{2, 2, {1.0, 0.01, 0.0, 1.0}};
  EXPECT_EQ(refused_part(phi, gamma, DenseMatrix{2, 2, {0.0, 0.0, 0.0, 1.0}}), ZohInverseError::Part::kNoise);
  try {
    (void)zoh_inverse(DenseMatrix{2, 2, {-0.5, 0.1, 0.0, 0.9}}, gamma, 0.01);
  } catch (const ZohInverseError& e) {
    EXPECT_NE(std::string(e.what()).find("negative real axis"), std::string::npos) << e.what();
  }
}

// (a) Γ far smaller (‖B‖ ≈ 1e−9) and far larger (≈ 1e6) than Φ − I: B comes back to its own
// precision, and so does Γ against its own norm. A tiny Γ is taken as it is (σ = 1: the
// logarithm is linear in the Γ block), a large one halved (σ > 1) so that it adds a square root
// or two to Φ's own (measured ≤ 2), not the ≈ log₂ 10⁶ = 20 it would unscaled. Measured over 2 × 12 seeded plants: B ≤ 1.3e−15 relative, Γ given
// back ≤ 1.9e−15, Φ given back ≤ 3.9e−15; asserted 3e−14 and 6e−14 (as for ordinary Γ above).
TEST(ZohInverse, RecoversATinyOrALargeGammaToItsOwnPrecision) {
  double worst_b = 0;
  double worst_gamma = 0;
  double worst_phi = 0;
  for (const double size : {1e-9, 1e6}) {
    for (std::uint64_t seed = 1; seed <= 12; ++seed) {
      std::mt19937_64 rng(0x2d2c7100 + seed);
      const std::size_t n = 2 + seed % 4;
      const DenseMatrix a = random_matrix(rng, n, n);
      const DenseMatrix b = random_matrix(rng, n, 1) * size;
      const double h = 1.0 / spectral_radius(a);
      DenseMatrix phi, gamma;
      c2d(a, b, h, phi, gamma);
      const ZohInverse r = zoh_inverse(phi, gamma, h);
      // Measured worst: B 1.3e-15, Γ back 1.9e-15, Φ back 3.9e-15; asserted a few times that.
      EXPECT_LT(rel(r.b, b), 6e-15) << "seed " << seed << " size " << size;
      EXPECT_LT(r.gamma_relative_error, 8e-15) << "seed " << seed << " size " << size;
      EXPECT_LT(r.phi_relative_error, 1.6e-14) << "seed " << seed << " size " << size;
      if (size < 1) {
        EXPECT_EQ(r.gamma_scale, 1.0);
      } else {  // halved, and at most two square roots more than Φ alone takes (unscaled: about 20)
        int phi_roots = 0;
        static_cast<void>(logm(phi, &phi_roots));
        EXPECT_GT(r.gamma_scale, 1.0) << "seed " << seed;
        EXPECT_LE(r.square_roots, phi_roots + 2) << "seed " << seed;
      }
      worst_b = std::fmax(worst_b, rel(r.b, b));
      worst_gamma = std::fmax(worst_gamma, r.gamma_relative_error);
      worst_phi = std::fmax(worst_phi, r.phi_relative_error);
    }
  }
  std::printf("zoh_inverse, tiny and large Gamma: worst relative error B %.3g, Gamma given back %.3g, Phi %.3g\n", worst_b,
              worst_gamma, worst_phi);
}

// (a) A tiny Γ whose continuous B is corrupted by 1e−6 relative: the whole-matrix error of
// [[Φ, Γ], [0, I]] stays below kZohInverseMaxError (‖Γ‖ ≪ ‖Φ‖ scales it down: the old check
// passed it), the block-wise check refuses it naming Γ.
TEST(ZohInverse, ACorruptedTinyGammaIsRefusedNamingGamma) {
  std::mt19937_64 rng(0x2d2c7200);
  const DenseMatrix a = random_matrix(rng, 3, 3);
  const DenseMatrix b = random_matrix(rng, 3, 1) * 1e-9;
  const double h = 1.0 / spectral_radius(a);
  DenseMatrix phi, gamma;
  c2d(a, b, h, phi, gamma);
  const ZohInverse r = zoh_inverse(phi, gamma, h);
  const ZohReconstruction good = check_zoh_reconstruction(phi, gamma, r.a, r.b, h);
  EXPECT_EQ(good.gamma_relative_error, r.gamma_relative_error);
  DenseMatrix corrupt = r.b;
  corrupt(1, 0) *= 1.0 + 1e-6;
  // The oracle of the old check: the whole augmented matrix given back, relative to its norm.
  DenseMatrix phi_back, gamma_back;
  c2d(r.a, corrupt, h, phi_back, gamma_back);
  const double whole = (norm1(phi_back - phi) + norm1(gamma_back - gamma)) / (norm1(phi) + 1.0);  // ≥ ‖ΔM‖₁/‖M‖₁
  EXPECT_LT(whole, kZohInverseMaxError);
  EXPECT_GT(rel(gamma_back, gamma), kZohInverseMaxError);
  try {
    (void)check_zoh_reconstruction(phi, gamma, r.a, corrupt, h);
    ADD_FAILURE() << "a corrupted Gamma passed";
  } catch (const ZohInverseError& e) {
    EXPECT_EQ(e.part(), ZohInverseError::Part::kGamma);
    EXPECT_NE(std::string(e.what()).find("samples back to Gamma"), std::string::npos) << e.what();
  }
}

/// Φ = rotation by π − δ (eigenvalues e^{±i(π − δ)}: δ rad from the negative real axis).
DenseMatrix rotation_near_pi(double delta) {
  const double c = std::cos(std::acos(-1.0) - delta);
  const double s = std::sin(std::acos(-1.0) - delta);
  return DenseMatrix{2, 2, {c, s, -s, c}};
}

std::string refusal_text(const DenseMatrix& phi, const DenseMatrix& gamma) {
  try {
    (void)zoh_inverse(phi, gamma, 0.01);
  } catch (const ZohInverseError& e) {
    EXPECT_EQ(e.part(), ZohInverseError::Part::kPhi) << e.what();
    return e.what();
  }
  ADD_FAILURE() << "not refused";
  return {};
}

// (b) The logarithm's failures say which: an eigenvalue just off the negative real axis (past
// the kZohInverseTolerance pre-check) makes a Denman–Beavers iterate singular (δ = 1e−8) or
// the reconstruction inaccurate (δ = 1e−6, measured 8.9e−5): both name the eigenvalue and its
// angle from the axis; logm() itself reports a singular iterate (on [[−1]]) apart from no
// convergence (on [[−4]], the real iteration of a negative number wanders).
TEST(ZohInverse, ALogarithmThatFailsSaysWhetherTheNegativeRealAxisIsTheCause) {
  const DenseMatrix gamma{2, 1, {0.0, 0.01}};
  const std::string singular = refusal_text(rotation_near_pi(1e-8), gamma);
  EXPECT_NE(singular.find("the principal logarithm failed (a Denman-Beavers square root met a singular iterate)"),
            std::string::npos) << singular;
  EXPECT_NE(singular.find("lies 1e-08 rad from the negative real axis"), std::string::npos) << singular;
  const std::string inaccurate = refusal_text(rotation_near_pi(1e-6), gamma);
  EXPECT_NE(inaccurate.find("samples back to Phi"), std::string::npos) << inaccurate;
  EXPECT_NE(inaccurate.find("lies 1e-06 rad from the negative real axis"), std::string::npos) << inaccurate;
  const auto failure = [](double v) {
    try {
      (void)logm(DenseMatrix{1, 1, {v}});
    } catch (const LogmError& e) {
      return e.failure();
    }
    ADD_FAILURE() << "logm of " << v << " succeeded";
    return LogmError::Failure::kTooManyRoots;
  };
  EXPECT_EQ(failure(-1.0), LogmError::Failure::kSingularIterate);
  EXPECT_EQ(failure(-4.0), LogmError::Failure::kNoConvergence);
  // 0.03 rad from the axis (ωh = π − 0.03): recovered (measured 2.6e−14 relative, asserted 1e−13).
  DenseMatrix phi, g;
  const DenseMatrix a{2, 2, {0.0, std::acos(-1.0) - 0.03, -(std::acos(-1.0) - 0.03), 0.0}};
  c2d(a, DenseMatrix{2, 1, {0.0, 1.0}}, 1.0, phi, g);
  const double near = rel(zoh_inverse(phi, g, 1.0).a, a);
  EXPECT_LT(near, 1e-13);
  std::printf("zoh_inverse: A 0.03 rad from the negative real axis, relative error %.3g\n", near);
}

// (d) κ₁(Φ) of a diagonal Φ = diag(e^{−h}, e^{−2000h}) at h = 0.01 is e^{−0.01}·e^{20} (closed
// form, ≈ 4.8e8: above kZohInverseWarnCondition, study check warns); measured 4.6e−15
// relative, asserted 3e−14. A is still recovered (diagonal: the logarithm acts per entry;
// measured 9.1e−16 relative, asserted 1e−14).
TEST(ZohInverse, EstimatesTheConditionOfPhi) {
  const DenseMatrix a{2, 2, {-1.0, 0.0, 0.0, -2000.0}};
  DenseMatrix phi, gamma;
  c2d(a, DenseMatrix{2, 1, {1.0, 1.0}}, 0.01, phi, gamma);
  const ZohInverse r = zoh_inverse(phi, gamma, 0.01);
  const double kappa = std::exp(-0.01) * std::exp(20.0);
  EXPECT_NEAR(r.phi_condition, kappa, kappa * 3e-14);
  EXPECT_GT(r.phi_condition, kZohInverseWarnCondition);
  EXPECT_LT(rel(r.a, a), 1e-14);
  std::printf("zoh_inverse: condition of Phi %.6g, relative error %.3g against its closed form; A relative error %.3g\n",
              r.phi_condition, std::fabs(r.phi_condition / kappa - 1), rel(r.a, a));
}

}  // namespace
}  // namespace oneshot::design
