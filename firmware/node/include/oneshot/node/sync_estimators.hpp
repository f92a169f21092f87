/// @file sync_estimators.hpp
/// @brief Estimators of the actuation-synchronized controller: each turns the report of
///        period k (τ_k, y_s,k, the input applied at t_{k−1}) into x̂ at t_k.
///
/// Plug-in interface: update(τ_us, y, u_applied) → Status, skip(u_held) → Status (a period
/// without a report, predicted over h), estimate() → x̂ at t_k.
/// update() never leaves a non-finite estimate: when x̂ (or P) turns NaN or ±∞ it resets to
/// the initial values it was given (reset(); the design's x0, P0) and returns
/// Status::kNonFinite.
///  * HalfKalmanEstimator — the core's half Kalman filter (half_kalman.hpp), unchanged
///    (brief §4, eqs 18–21 corrected): the echo is its applied input.
///  * SampledStatePredictor — no filter (eq. 10): x̂_k = Φ(τ_k) y_s,k + Γ(τ_k) u_{k−1},
///    for plants that measure the whole state (C = I, P = N).
#pragma once

#include <cstddef>
#include <cstdint>

#include "oneshot/finite.hpp"
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
  /// Also the values a non-finite result resets it to.
  constexpr void reset(const StateVec& x0, const Cov& p0, const InputVec& u0) {
    x0_ = x0;
    p0_ = p0;
    u0_ = u0;
    filter_.reset(x0, p0, u0);
  }
  /// Report of period k: predicts from t_{k−1} with the echoed input, corrects with y, predicts to t_k.
  /// A non-finite x̂⁻ or P resets the filter to (x0, P0, u0): Status::kNonFinite.
  [[nodiscard]] constexpr Status update(std::int32_t tau_us, const OutputVec& y, const InputVec& u_applied) {
    filter_.set_applied_input(u_applied);
    const Status s = filter_.update(tau_us, y);
    if (all_finite(filter_.prediction()) && all_finite(filter_.covariance())) return s;
    filter_.reset(x0_, p0_, u0_);
    return Status::kNonFinite;
  }
  /// A period without a report: predicts over h from t_k with the input held there (the
  /// last command). Reset and Status::kNonFinite as update().
  [[nodiscard]] constexpr Status skip(const InputVec& u_held) {
    filter_.set_applied_input(u_held);
    const Status s = filter_.skip_period();
    if (all_finite(filter_.prediction()) && all_finite(filter_.covariance())) return s;
    filter_.reset(x0_, p0_, u0_);
    return Status::kNonFinite;
  }
  /// x̂⁻_k: the estimate at t_k.
  constexpr const StateVec& estimate() const { return filter_.prediction(); }
  /// The core filter (covariance, gain).
  constexpr const Filter& filter() const { return filter_; }

 private:
  Filter filter_;
  StateVec x0_{};
  Cov p0_{};
  InputVec u0_{};
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
  /// Report of period k: x̂_k = Φ(τ_k) y + Γ(τ_k) u_{k−1}; a non-finite result leaves
  /// x̂ = 0 (no memory to reset) and returns Status::kNonFinite.
  [[nodiscard]] constexpr Status update(std::int32_t tau_us, const OutputVec& y, const InputVec& u_applied) {
    typename Disc::Triple d{NoInit{}};
    const Status s = disc_->discretize(disc_->quantize(tau_us), d, WithQd::kNo);
    x_ = predict_state<Fmt, Structure>(d, y, u_applied);
    if (all_finite(x_)) return s;
    x_ = StateVec{};
    return Status::kNonFinite;
  }
  /// A period without a report: nothing to do (no memory across reports).
  [[nodiscard]] constexpr Status skip(const InputVec&) { return Status::kOk; }
  /// x̂_k.
  constexpr const StateVec& estimate() const { return x_; }

 private:
  const Disc* disc_;
  StateVec x_{};
};

}  // namespace oneshot::node
