/// @file sampling_sync_laws.hpp
/// @brief Control laws of the sampling-synchronized baseline (networked-actuation brief §5),
///        plug-ins of ControllerNode (controller_node.hpp) in on-arrival mode.
///
/// The sensor samples on its own timer at kh (seq = k), the controller computes on arrival
/// and the actuator applies on arrival; every law targets period k's set-point and clamps
/// u to the actuator's range (counted):
///  * StateFeedbackLaw (S, I):      u_k = u_ref − L (y_k − x_ref)              (C = I)
///  * PeriodicKalmanLaw (SK, IK):   the core's standard Kalman filter at period h,
///                                  u_k = u_ref − L (x̂_k − x_ref)
///  * DelayCompensatedLaw (S+):     u_k = u_ref − L_x (y_k − x_ref) − L_u (u_{k−1} − u_ref), the LQR of
///                                  eq. 8 on [x_k; u_{k−1}] for the mean τ_io (designed on the host)
#pragma once

#include <cstddef>
#include <cstdint>

#include "oneshot/finite.hpp"
#include "oneshot/node/law_result.hpp"
#include "oneshot/node/message.hpp"
#include "oneshot/node/square_wave_reference.hpp"
#include "oneshot/standard_kalman.hpp"

namespace oneshot::node {

/// Static state feedback on the measured state (C = I).
template <typename S, std::size_t N, std::size_t M, typename Reference>
struct StateFeedbackLaw {
  Matrix<S, M, N> l;          ///< L.
  Vector<S, M> u_min;         ///< Actuator range, low end.
  Vector<S, M> u_max;         ///< Actuator range, high end.
  Reference reference;        ///< Set-point per period.
  std::uint32_t saturated = 0;  ///< Commands clamped.
  /// u_k = u_ref − L (y_k − x_ref); sends on every fresh sample.
  [[nodiscard]] LawResult compute(const Message<VectorPayload<S, N>>& m, bool fresh, McuInstant, Vector<S, M>& u) {
    if (!fresh) return LawResult::kNone;
    u = reference.input(m.seq) - l * (m.payload.value - reference.state(m.seq));
    if (saturate(u, u_min, u_max)) ++saturated;
    return LawResult::kSend;
  }
};

/// The core's standard (periodic) Kalman filter, then state feedback.
template <typename Fmt, typename Structure, typename Reference>
class PeriodicKalmanLaw {
 public:
  using S = typename Fmt::State;
  static constexpr std::size_t kN = Structure::kStates;
  static constexpr std::size_t kM = Structure::kInputs;
  static constexpr std::size_t kP = Structure::kOutputs;
  using Filter = StandardKalman<Fmt, Structure>;  ///< The core filter.

  /// Filter over `design` (must outlive it); range and reference as in StateFeedbackLaw.
  constexpr PeriodicKalmanLaw(const typename Filter::Design& design, NoiseModel noise, const Vector<S, kM>& u_min,
                              const Vector<S, kM>& u_max, const Reference& reference)
      : design_(&design), filter_(design, noise), u_min_(u_min), u_max_(u_max), reference_(reference) {}
  /// The filter (reset).
  constexpr Filter& filter() { return filter_; }
  /// Commands clamped.
  constexpr std::uint32_t saturated() const { return saturated_; }
  /// Corrects with y_k (after predicting over h with the last command), u_k from x̂_k.
  /// A non-finite x̂ or P resets the filter to x̂ = 0, the design's P0, u = 0 (counted in
  /// resets()) and sends nothing for this sample.
  [[nodiscard]] LawResult compute(const Message<VectorPayload<S, kP>>& m, bool fresh, McuInstant, Vector<S, kM>& u) {
    if (!fresh) return LawResult::kNone;
    if (!is_exact(filter_.update(0, m.payload.value))) ++faults_;
    if (!all_finite(filter_.prediction()) || !all_finite(filter_.covariance())) {
      filter_.reset(Vector<S, kN>{}, design_->p0, Vector<S, kM>{});
      ++resets_;
      return LawResult::kReset;
    }
    u = reference_.input(m.seq) - design_->l * (filter_.prediction() - reference_.state(m.seq));
    if (saturate(u, u_min_, u_max_)) ++saturated_;
    filter_.set_applied_input(u);
    return LawResult::kSend;
  }
  /// Filter runs whose status was not exact.
  constexpr std::uint32_t faults() const { return faults_; }
  /// Filter runs that turned non-finite (reset).
  constexpr std::uint32_t resets() const { return resets_; }

 private:
  const typename Filter::Design* design_;
  Filter filter_;
  Vector<S, kM> u_min_;
  Vector<S, kM> u_max_;
  Reference reference_;
  std::uint32_t saturated_ = 0;
  std::uint32_t faults_ = 0;
  std::uint32_t resets_ = 0;
};

/// State feedback with the previous command as an extra state (eq. 8's delay model).
template <typename S, std::size_t N, std::size_t M, typename Reference>
struct DelayCompensatedLaw {
  Matrix<S, M, N> lx;         ///< L_x.
  Matrix<S, M, M> lu;         ///< L_u.
  Vector<S, M> u_min;         ///< Actuator range, low end.
  Vector<S, M> u_max;         ///< Actuator range, high end.
  Reference reference;        ///< Set-point per period.
  Vector<S, M> u_prev{};      ///< u_{k−1}: the last command sent.
  std::uint32_t saturated = 0;  ///< Commands clamped.
  /// u_k = u_ref − L_x (y_k − x_ref) − L_u (u_{k−1} − u_ref).
  [[nodiscard]] LawResult compute(const Message<VectorPayload<S, N>>& m, bool fresh, McuInstant, Vector<S, M>& u) {
    if (!fresh) return LawResult::kNone;
    u = reference.input(m.seq) - lx * (m.payload.value - reference.state(m.seq)) - lu * (u_prev - reference.input(m.seq));
    if (saturate(u, u_min, u_max)) ++saturated;
    u_prev = u;
    return LawResult::kSend;
  }
};

}  // namespace oneshot::node
