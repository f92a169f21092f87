/// @file sampled_model.hpp
/// @brief The plant and its cost per period: Φ(h), Γ(h), Q_d(h), the sampled cost (host).
///
/// Continuous plants are sampled with the core's scaled Taylor exponential repeated on
/// run-time sized matrices (dense_ops.hpp expm): the operations of the core's
/// GenericDiscretizer (per-µs model × integer τ, Van Loan for Q_d, upper triangle
/// mirrored), so Φ(h), Γ(h), Q_d(h) are the same bits the core computes. Discrete plants
/// are taken as given. See controller_synthesis.hpp for the equations.
#pragma once

#include <stdexcept>
#include <string>

#include "oneshot/design/dense_matrix.hpp"
#include "oneshot/design/plant_description.hpp"

namespace oneshot::design {

/// The plant per period.
struct SampledModel {
  DenseMatrix phi;         ///< Φ(h).
  DenseMatrix gamma;       ///< Γ(h).
  DenseMatrix gamma_w;     ///< Disturbance input per step (empty when q = 0).
  DenseMatrix qd;          ///< Per-step process covariance (exact Q_d(h) for continuous plants).
  DenseMatrix qc;          ///< Continuous total intensity (empty for discrete plants).
  DenseMatrix q_constant;  ///< The per-step constant Q of the original design.
};

/// Samples the plant at its period; std::domain_error when an exponential cannot be scaled.
SampledModel sample_plant(const PlantDescription& plant);

/// Per-step cost weights.
struct SampledCost {
  DenseMatrix q1, q12, q2;  ///< [[Q1, Q12], [Q12ᵀ, Q2]]; empty for CostForm::kNone.
};

/// The continuous cost sampled exactly over h, or the discrete weights with Q12 = 0.
SampledCost sample_cost(const PlantDescription& plant);

/// Eigenvalues λ of Φ refused by zoh_inverse(): |λ| ≤ kZohInverseTolerance·max(1, ‖Φ‖₁)
/// (singular: log 0), or Re λ < 0 with |Im λ| ≤ kZohInverseTolerance·|λ| (the closed negative
/// real axis: no real principal logarithm, or not a unique one).
inline constexpr double kZohInverseTolerance = 1e-10;
/// Largest relative error ‖e^{[[A, B], [0, 0]]h} − [[Φ, Γ], [0, I]]‖₁ / ‖[[Φ, Γ], [0, I]]‖₁
/// (and ‖Q_d(Q_c) − Q_d‖₁ / ‖Q_d‖₁ for the noise) zoh_inverse() accepts.
inline constexpr double kZohInverseMaxError = 1e-10;

/// The continuous plant whose zero-order-hold sampling at h is a discrete one (MATLAB d2c 'zoh').
struct ZohInverse {
  DenseMatrix a;                 ///< A (1/s, n×n), eigenvalues with |Im λ| < π/h (the principal logarithm).
  DenseMatrix b;                 ///< B (n×m).
  double relative_error = 0;     ///< Of the reconstruction e^{[[A, B], [0, 0]]h} against [[Φ, Γ], [0, I]] (‖·‖₁).
  int square_roots = 0;          ///< Square roots taken before the series of log(I + Y).
  DenseMatrix qc;                ///< Q_c (n×n, unit²/s) whose Van Loan sampling at h is Q_d (empty without Q_d).
  double noise_relative_error = 0;  ///< Of Q_d(Q_c) against Q_d (‖·‖₁), 0 without Q_d.
};

/// Why zoh_inverse() refuses: the part of the discrete plant at fault, and a one-line reason.
class ZohInverseError : public std::domain_error {
 public:
  /// Which input is refused.
  enum class Part { kPhi, kNoise };
  /// A refusal of `part` for `reason`.
  ZohInverseError(Part part, const std::string& reason) : std::domain_error(reason), part_(part) {}
  /// Φ (no real principal logarithm, singular, reconstruction off) or Q_d (no PSD intensity).
  Part part() const { return part_; }

 private:
  Part part_;
};

/// The exact inverse of ZOH sampling: A, B from the principal logarithm of the augmented
/// M = [[Φ, Γ], [0, I]] (log M / h = [[A, B], [0, 0]]) by inverse scaling and squaring
/// (product-form Denman–Beavers square roots until ‖X − I‖₁ < 1/4, the series of log(I + Y)
/// to 40 terms, times 2ˢ); with a non-empty `qd`, the intensity Q_c whose Van Loan sampling
/// over h is Q_d (the linear map ∫₀ʰ e^{As}·e^{Aᵀs} ds solved on vec Q_c). ZohInverseError
/// naming Φ when an eigenvalue of Φ lies on the closed negative real axis or at 0 (within
/// kZohInverseTolerance) or the reconstruction is off by more than kZohInverseMaxError, naming
/// the noise when Q_c is not positive semidefinite or does not give back Q_d.
ZohInverse zoh_inverse(const DenseMatrix& phi, const DenseMatrix& gamma, double h_s, const DenseMatrix& qd = {});

/// The principal matrix logarithm by the inverse scaling and squaring of zoh_inverse() (no
/// eigenvalue check; `square_roots` receives s). std::domain_error when a square root does not
/// converge or X − I does not fall below 1/4 in 64 roots.
DenseMatrix logm(const DenseMatrix& m, int* square_roots = nullptr);

}  // namespace oneshot::design
