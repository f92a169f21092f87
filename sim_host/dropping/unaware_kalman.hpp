/// @file unaware_kalman.hpp
/// @brief The dropping study's delay-unaware baseline estimator (E5): a standard Kalman filter
///        on the core's predict/correct that takes the newest packet arrived in the period as y_k.
#pragma once

#include <cstdint>
#include <optional>

#include "dropping_plant.hpp"
#include "oneshot/kalman_correction.hpp"
#include "oneshot/node/buffered_kalman.hpp"
#include "oneshot/number_format.hpp"
#include "oneshot/one_shot_predictor.hpp"
#include "oneshot/plant_structure.hpp"

namespace oneshot::dropping {

/// The delay-unaware baseline: a standard KF (core predict/correct) that takes the newest
/// packet arrived in the period as y_k (predict only when none arrived).
class UnawareKalman {
 public:
  using Fmt = UniformFormat<double>;             ///< Double arithmetic throughout.
  using Structure = DenseStructure<kN, kM, kP>;  ///< Dense Φ, Γ, C.
  using StateVec = Vector<double, kN>;           ///< x.
  using InputVec = Vector<double, kM>;           ///< u.
  using OutputVec = Vector<double, kP>;          ///< y.
  using Cov = Matrix<double, kN, kN>;            ///< P.

  /// The filter of model `m` (kept by reference: it must outlive the filter), x̂₀ = 0, P₀ = `p0`.
  UnawareKalman(const node::BufferedKalmanModel<Fmt, kN, kM, kP>& m, const Cov& p0) : m_(&m), p_(p0) {}
  /// Step k: x̂ ← Φx̂ + Γu, P ← ΦPΦᵀ + Q (from the second step on), then the correction with
  /// `y` when a packet arrived (K = PCᵀ(CPCᵀ + R)⁻¹); the core's status.
  Status step(const std::optional<OutputVec>& y) {
    if (!first_) {
      x_ = predict_state<Fmt, Structure>(m_->step, x_, u_);
      p_ = predict_covariance<Fmt, Structure>(m_->step, p_, NoiseModel::kConstant, m_->q);
    }
    first_ = false;
    corrections_ = 0;
    if (!y) return Status::kOk;
    corrections_ = 1;
    Matrix<double, kN, kP> k;
    return correct<Fmt, Structure, CovarianceUpdate::kSymmetric>(x_, p_, *y, m_->c, m_->r, k);
  }
  /// The input u_k applied over the step (taken by the next prediction).
  void set_applied_input(const InputVec& u) { u_ = u; }
  /// x̂(k|k).
  const StateVec& estimate() const { return x_; }
  /// P(k|k).
  const Cov& covariance() const { return p_; }
  /// Corrections in the last step (0 or 1).
  std::uint32_t last_corrections() const { return corrections_; }

 private:
  const node::BufferedKalmanModel<Fmt, kN, kM, kP>* m_;
  StateVec x_{};
  Cov p_;
  InputVec u_{};
  bool first_ = true;
  std::uint32_t corrections_ = 0;
};

}  // namespace oneshot::dropping
