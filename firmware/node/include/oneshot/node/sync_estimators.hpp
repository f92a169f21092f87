/// @file sync_estimators.hpp
/// @brief Estimators of the actuation-synchronized controller: each turns the report of
///        period k (τ_k, y_s,k, the input applied at t_{k−1}) into x̂ at t_k.
///
/// Plug-in interface: update(τ_us, y, u_applied) → Status, estimate() → x̂ at t_k.
///  * HalfKalmanEstimator — the core's half Kalman filter (half_kalman.hpp), unchanged
///    (brief §4, eqs 18–21 corrected): the echo is its applied input.
///  * SampledStatePredictor — no filter (eq. 10): x̂_k = Φ(τ_k) y_s,k + Γ(τ_k) u_{k−1},
///    for plants that measure the whole state (C = I, P = N).
#pragma once

#include <cstddef>
#include <cstdint>

#include "oneshot/half_kalman.hpp"
#include "oneshot/one_shot_predictor.hpp"
#include "oneshot/status.hpp"

namespace oneshot::node {

/// The core's half Kalman filter behind the synchronized controller's interface.
template <typename Fmt, typename Structure, typename Disc>
class HalfKalmanEstimator {
 public:
  using Filter = HalfKalman<Fmt, Structure, Disc>;  ///< The core filter.
  using StateVec = typename Filter::StateVec;       ///< x̂.
  using OutputVec = typename Filter::OutputVec;     ///< y.
  using InputVec = typename Filter::InputVec;       ///< u.
  using Cov = typename Filter::Cov;                 ///< P.

  /// Filter over `design` and `disc` (both must outlive it) with process noise `noise`.
  constexpr HalfKalmanEstimator(const typename Filter::Design& design, const Disc& disc, NoiseModel noise)
      : filter_(design, disc, noise) {}
  /// Estimate x0 with covariance p0 at an actuation instant, input u0 in force.
  constexpr void reset(const StateVec& x0, const Cov& p0, const InputVec& u0) { filter_.reset(x0, p0, u0); }
  /// Report of period k: predicts from t_{k−1} with the echoed input, corrects with y, predicts to t_k.
  constexpr Status update(std::int32_t tau_us, const OutputVec& y, const InputVec& u_applied) {
    filter_.set_applied_input(u_applied);
    return filter_.update(tau_us, y);
  }
  /// x̂⁻_k: the estimate at t_k.
  constexpr const StateVec& estimate() const { return filter_.prediction(); }
  /// The core filter (covariance, gain).
  constexpr const Filter& filter() const { return filter_; }

 private:
  Filter filter_;
};

/// No filter: the sampled state predicted over τ (eq. 10); C = I.
template <typename Fmt, typename Structure, typename Disc>
class SampledStatePredictor {
 public:
  static constexpr std::size_t kN = Structure::kStates;
  static constexpr std::size_t kM = Structure::kInputs;
  static_assert(Structure::kOutputs == kN, "the filterless predictor needs the whole state measured (C = I)");
  using StateVec = Vector<typename Fmt::State, kN>;  ///< x̂ and y.
  using OutputVec = StateVec;                        ///< y = x.
  using InputVec = Vector<typename Fmt::Input, kM>;  ///< u.

  /// Predictor over `disc` (must outlive it).
  constexpr explicit SampledStatePredictor(const Disc& disc) : disc_(&disc) {}
  /// Report of period k: x̂_k = Φ(τ_k) y + Γ(τ_k) u_{k−1}.
  constexpr Status update(std::int32_t tau_us, const OutputVec& y, const InputVec& u_applied) {
    typename Disc::Triple d{NoInit{}};
    const Status s = disc_->discretize(disc_->quantize(tau_us), d, WithQd::kNo);
    x_ = predict_state<Fmt, Structure>(d, y, u_applied);
    return s;
  }
  /// x̂_k.
  constexpr const StateVec& estimate() const { return x_; }

 private:
  const Disc* disc_;
  StateVec x_{};
};

}  // namespace oneshot::node
