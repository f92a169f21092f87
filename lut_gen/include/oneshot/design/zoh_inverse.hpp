/// @file zoh_inverse.hpp
/// @brief The exact inverse of zero-order-hold sampling (MATLAB d2c 'zoh', host): the continuous
///        plant (A, B, Q_c) whose sampling at h is a given discrete one (Φ, Γ, Q_d), by the
///        principal matrix logarithm (inverse scaling and squaring, Denman–Beavers square roots),
///        checked block by block by sampling it back.
#pragma once

#include <cstdint>
#include <stdexcept>
#include <string>

#include "oneshot/design/dense_matrix.hpp"

namespace oneshot::design {

/// Eigenvalues λ of Φ refused by zoh_inverse(): |λ| ≤ kZohInverseTolerance·max(1, ‖Φ‖₁)
/// (singular: log 0), or Re λ < 0 with |Im λ| ≤ kZohInverseTolerance·|λ| (the closed negative
/// real axis: no real principal logarithm, or not a unique one). About 10⁶ unit roundoffs: an
/// eigenvalue computed from a Φ that has one there lands within it.
inline constexpr double kZohInverseTolerance = 1e-10;
/// Largest relative error of the reconstruction zoh_inverse() accepts, block by block, each
/// against its own norm: ‖Φ(A, h) − Φ‖₁ / ‖Φ‖₁, ‖Γ(A, B, h) − Γ‖₁ / ‖Γ‖₁ (and ‖Q_d(Q_c) − Q_d‖₁ /
/// ‖Q_d‖₁ for the noise). Round trips measure ≤ 1.3e−14 (zoh_inverse_test.cpp): 10⁴ times that
/// still refuses an answer off in its 11th digit.
inline constexpr double kZohInverseMaxError = 1e-10;
/// κ₁(Φ) = ‖Φ‖₁‖Φ⁻¹‖₁ above which `study check` warns that Φ is near-singular: the logarithm's
/// sensitivity at an eigenvalue λ is 1/|λ|, so A is recovered to about κ₁·u ≈ κ₁·1.1e−16
/// relative, from here on worse than kZohInverseMaxError, which the reconstruction (a backward
/// error) still passes.
inline constexpr double kZohInverseWarnCondition = 1e6;

/// logm(): the series of log(I + Y) is summed once ‖Y‖₁ = ‖X − I‖₁ falls below this. Its
/// remainder after kLogmSeriesTerms terms is ≤ ‖Y‖^{K+1}/((K+1)(1 − ‖Y‖)) < 10⁻²⁵ at 1/4, far
/// below rounding, while one more square root (the price of a smaller radius) costs about an ulp.
inline constexpr double kLogmSeriesRadius = 0.25;
/// logm(): terms of the series of log(I + Y) (Horner); see kLogmSeriesRadius.
inline constexpr int kLogmSeriesTerms = 40;
/// logm(): square roots before X − I must have fallen below kLogmSeriesRadius. Each root halves
/// log X, and |log λ| ≤ 745 for any double λ > 0 (≈ 2¹⁰) plus an argument ≤ π: some 12 roots
/// suffice for a normal Φ of any spectrum; 64 means the roots are not converging to I.
inline constexpr int kLogmMaxSquareRoots = 64;
/// logm(): Denman–Beavers iterations per square root. Quadratic once near I, so some ten for a
/// spectrum well off the negative real axis; 100 is reached only when the iterates do not
/// approach I (a spectrum on the axis: logm of [[−4]] does not converge).
inline constexpr int kSquareRootMaxIterations = 100;
/// logm(): a square root stops one iteration after ‖M − I‖₁ ≤ this (quadratic convergence: that
/// last iteration is at rounding; some 900 unit roundoffs leave room for the cancellation in M − I).
inline constexpr double kSquareRootStop = 1e-13;

/// The continuous plant whose zero-order-hold sampling at h is a discrete one (MATLAB d2c 'zoh').
struct ZohInverse {
  DenseMatrix a;                    ///< A (1/s, n×n), eigenvalues with |Im λ| < π/h (the principal logarithm).
  DenseMatrix b;                    ///< B (n×m).
  double relative_error = 0;        ///< Of e^{[[A, B], [0, 0]]h} against [[Φ, Γ], [0, I]] as a whole (‖·‖₁).
  double phi_relative_error = 0;    ///< ‖Φ(A, h) − Φ‖₁ / ‖Φ‖₁.
  double gamma_relative_error = 0;  ///< ‖Γ(A, B, h) − Γ‖₁ / ‖Γ‖₁ (0 when Γ = 0 comes back 0).
  double gamma_scale = 1;           ///< σ = 2ᵏ ≥ 1: the logarithm is taken of [[Φ, Γ/σ], [0, I]] (zoh_inverse()).
  double phi_condition = 1;         ///< κ₁(Φ) = ‖Φ‖₁‖Φ⁻¹‖₁ (see kZohInverseWarnCondition).
  int square_roots = 0;             ///< Square roots taken before the series of log(I + Y).
  DenseMatrix qc;                   ///< Q_c (n×n, unit²/s) whose Van Loan sampling at h is Q_d (empty without Q_d).
  double noise_relative_error = 0;  ///< Of Q_d(Q_c) against Q_d (‖·‖₁), 0 without Q_d.
};

/// Why zoh_inverse() refuses: the part of the discrete plant at fault, and a one-line reason.
class ZohInverseError : public std::domain_error {
 public:
  /// Which input is refused.
  enum class Part { kPhi, kGamma, kNoise };
  /// A refusal of `part` for `reason`.
  ZohInverseError(Part part, const std::string& reason) : std::domain_error(reason), part_(part) {}
  /// Φ (no real principal logarithm, singular, the logarithm failed, Φ not given back), Γ (not
  /// given back) or Q_d (no PSD intensity).
  Part part() const { return part_; }

 private:
  Part part_;
};

/// Why logm() fails.
class LogmError : public std::domain_error {
 public:
  /// The step that failed.
  enum class Failure : std::uint8_t {
    kSingularIterate,  ///< A Denman–Beavers iterate is singular to working precision.
    kNoConvergence,    ///< A square root did not converge in kSquareRootMaxIterations.
    kTooManyRoots,     ///< X − I did not fall below kLogmSeriesRadius in kLogmMaxSquareRoots roots.
  };
  /// A failure `failure` described by `reason`.
  LogmError(Failure failure, const std::string& reason) : std::domain_error(reason), failure_(failure) {}
  /// The step that failed.
  Failure failure() const { return failure_; }

 private:
  Failure failure_;
};

/// The block-wise check of a continuous equivalent: [[A, B], [0, 0]]h exponentiated and compared
/// with [[Φ, Γ], [0, I]], each block against its own norm.
struct ZohReconstruction {
  double relative_error = 0;        ///< ‖e^{[[A, B], [0, 0]]h} − [[Φ, Γ], [0, I]]‖₁ / ‖[[Φ, Γ], [0, I]]‖₁.
  double phi_relative_error = 0;    ///< ‖Φ(A, h) − Φ‖₁ / ‖Φ‖₁.
  double gamma_relative_error = 0;  ///< ‖Γ(A, B, h) − Γ‖₁ / ‖Γ‖₁ (0 when both are 0).
};

/// Samples (A, B) back at h (one exponential of [[A, B], [0, 0]]h) and measures it against
/// (Φ, Γ) block by block; ZohInverseError naming Φ or Γ when that block is off by more than
/// kZohInverseMaxError relative to its own norm. The whole-matrix error alone would let a bad
/// Γ pass when ‖Γ‖ ≪ ‖Φ‖.
ZohReconstruction check_zoh_reconstruction(const DenseMatrix& phi, const DenseMatrix& gamma, const DenseMatrix& a,
                                           const DenseMatrix& b, double h_s);

/// The exact inverse of ZOH sampling: A, B from the principal logarithm of the augmented
/// M = [[Φ, Γ/σ], [0, I]] (log M / h = [[A, B/σ], [0, 0]]) by inverse scaling and squaring
/// (logm). σ = 2ᵏ ≥ 1 is the least with ‖Γ/σ‖₁ ≤ max(2‖Φ − I‖₁, kLogmSeriesRadius/2): a large Γ
/// then adds a square root or two to Φ's own (each costs A some accuracy; unscaled, a Γ 2ʲ times
/// ‖Φ − I‖ would add about j), and no σ < 1 is needed for
/// a small Γ, every operation on the Γ block being linear in it (B comes back to its own
/// precision, and check_zoh_reconstruction() checks Γ against its own norm);
/// with a non-empty `qd`, the intensity Q_c whose Van Loan sampling over h is Q_d (the linear map
/// ∫₀ʰ e^{As}·e^{Aᵀs} ds solved on vec Q_c). ZohInverseError naming Φ when an eigenvalue of Φ
/// lies on the closed negative real axis or at 0 (within kZohInverseTolerance), when the
/// logarithm fails (the reason says whether an eigenvalue lies near the negative real axis or
/// the iteration did not converge) or Φ does not come back; naming Γ when Γ does not come back
/// (check_zoh_reconstruction); naming the noise when Q_c is not positive semidefinite or does
/// not give back Q_d.
ZohInverse zoh_inverse(const DenseMatrix& phi, const DenseMatrix& gamma, double h_s, const DenseMatrix& qd = {});

/// The principal matrix logarithm by inverse scaling and squaring: product-form Denman–Beavers
/// square roots until ‖X − I‖₁ < kLogmSeriesRadius, the series of log(I + Y) to
/// kLogmSeriesTerms terms, times 2ˢ (no eigenvalue check; `square_roots` receives s). LogmError
/// saying which step failed.
DenseMatrix logm(const DenseMatrix& m, int* square_roots = nullptr);

}  // namespace oneshot::design
