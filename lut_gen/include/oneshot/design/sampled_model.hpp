/// @file sampled_model.hpp
/// @brief The plant and its cost per period: Φ(h), Γ(h), Q_d(h), the sampled cost (host).
///
/// Continuous plants are sampled with the core's scaled Taylor exponential repeated on
/// run-time sized matrices (dense_ops.hpp expm): the operations of the core's
/// GenericDiscretizer (per-µs model × integer τ, Van Loan for Q_d, upper triangle
/// mirrored), so Φ(h), Γ(h), Q_d(h) are the same bits the core computes. Discrete plants
/// are taken as given (their continuous equivalent: zoh_inverse.hpp). See controller_synthesis.hpp
/// for the equations.
#pragma once

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

}  // namespace oneshot::design
