/// @file kalman_filter_base.hpp
/// @brief What the task-model filters (standard, half, complete) share: the design, the
///        noise model, the KalmanEstimator they run on, their types and read accessors; the
///        half and complete filters also the discretizer and the τ of a job.
#pragma once

#include <cstddef>

#include "oneshot/controller_design.hpp"
#include "oneshot/kalman_estimator.hpp"
#include "oneshot/time_us.hpp"

namespace oneshot {

/// Base of StandardKalman, HalfKalman and CompleteKalman (no virtual functions: each
/// filter is used through its own type).
template <typename Fmt, typename Structure, CovarianceUpdate kForm>
class KalmanFilterBase : public StructureTypes<Fmt, Structure> {
 public:
  using Core = KalmanEstimator<Fmt, Structure, kForm>;    ///< The estimator it runs on.
  using Cov = typename Core::Cov;                         ///< P.
  using Gain = typename Core::Gain;                       ///< K.

  /// The covariance the estimator holds (see each filter for the instant).
  constexpr const Cov& covariance() const { return core_.covariance(); }
  /// The gain of the last correction.
  constexpr const Gain& gain() const { return core_.gain(); }
  /// The estimator underneath.
  constexpr const Core& core() const { return core_; }

  /// Filter over `design` (must outlive it), reset to x̂ = 0, P = design.p0 (a filter's
  /// other state starts at its reset value too: u = 0).
  constexpr KalmanFilterBase(const typename KalmanFilterBase::Design& design, NoiseModel noise)
      : design_(&design), noise_(noise) {
    core_.reset({}, design.p0);
  }

 protected:
  const typename KalmanFilterBase::Design* design_;  ///< Controller design.
  NoiseModel noise_;      ///< Constant Q or exact Q_d(Δt).
  Core core_{};           ///< The estimator.
};

/// Base of HalfKalman and CompleteKalman: Φ, Γ, Q_d(Δt) from the discretizer Disc (a
/// GenericDiscretizer or TableDiscretizer) over intervals set by the τ of each job.
template <typename Fmt, typename Structure, typename Disc, CovarianceUpdate kForm>
class DiscretizedFilterBase : public KalmanFilterBase<Fmt, Structure, kForm> {
  using FilterBase = KalmanFilterBase<Fmt, Structure, kForm>;

 public:
  /// Filter over `design` and `disc` (both must outlive it), reset as KalmanFilterBase.
  constexpr DiscretizedFilterBase(const typename FilterBase::Design& design, const Disc& disc, NoiseModel noise)
      : FilterBase(design, noise), disc_(&disc) {}

 protected:
  /// The τ a job works with: bounded to ±kMaxTauUs (kClamped beyond), then put on the
  /// discretizer's sub-grid (its quantize()).
  [[nodiscard]] constexpr Status job_tau(DurationUs& tau_us) const {
    const Status status = bound_tau(tau_us);
    tau_us = disc_->quantize(tau_us);
    return status;
  }

  const Disc* disc_;  ///< Discretizer (Φ, Γ, Q_d of an interval).
};

}  // namespace oneshot
