/// @file kalman_filter_base.hpp
/// @brief What the task-model filters (standard, half, complete) share: the design, the
///        noise model, the KalmanEstimator they run on, their types and read accessors.
#pragma once

#include <cstddef>

#include "oneshot/kalman_estimator.hpp"

namespace oneshot {

/// Base of StandardKalman, HalfKalman and CompleteKalman (no virtual functions: each
/// filter is used through its own type).
template <typename Fmt, typename Structure, CovarianceUpdate kForm>
class KalmanFilterBase {
 public:
  static constexpr std::size_t kN = Structure::kStates;   ///< n.
  static constexpr std::size_t kM = Structure::kInputs;   ///< m.
  static constexpr std::size_t kP = Structure::kOutputs;  ///< p.
  using Design = ControllerDesign<Fmt, kN, kM, kP>;       ///< Gains, noise and model at h.
  using Core = KalmanEstimator<Fmt, Structure, kForm>;    ///< The estimator it runs on.
  using StateVec = typename Core::StateVec;               ///< x̂.
  using OutputVec = typename Core::OutputVec;             ///< y.
  using InputVec = typename Core::InputVec;               ///< u.
  using Cov = typename Core::Cov;                         ///< P.
  using Gain = typename Core::Gain;                       ///< K.

  /// The covariance the estimator holds (see each filter for the instant).
  constexpr const Cov& covariance() const { return core_.covariance(); }
  /// The gain of the last correction.
  constexpr const Gain& gain() const { return core_.gain(); }
  /// The estimator underneath.
  constexpr const Core& core() const { return core_; }

 protected:
  /// Filter over `design` (must outlive it).
  constexpr KalmanFilterBase(const Design& design, NoiseModel noise) : design_(&design), noise_(noise) {}

  const Design* design_;  ///< Controller design.
  NoiseModel noise_;      ///< Constant Q or exact Q_d(Δt).
  Core core_{};           ///< The estimator.
};

}  // namespace oneshot
