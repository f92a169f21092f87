/// @file estimator_memory.hpp
/// @brief The linear memory of each estimator of study 000, read from and written into copies
///        of the firmware objects (the linear board's analytic mode probes their affine map).
///
/// Memory between two jobs: x̂ (the state the next update starts from: the filter core's
/// estimate, or the deadbeat observer's) and the inputs it predicts with: u_last (the input
/// of the last job, set_applied_input) and u_prev (the one before: only the complete Kalman
/// filter uses it, from the sample to t_k). The covariance P, the gains and τ stay as the copy
/// has them: they depend on the timing only.
#pragma once

#include "oneshot/complete_kalman.hpp"
#include "oneshot/deadbeat_observer.hpp"
#include "oneshot/half_kalman.hpp"
#include "oneshot/standard_kalman.hpp"
#include "oneshot/structured_ops.hpp"

#include <type_traits>

namespace oneshot::sim {

/// True for the standard Kalman filter.
template <typename T>
struct is_standard_kalman : std::false_type {};
/// True for the standard Kalman filter.
template <typename Fmt, typename S, CovarianceUpdate kF>
struct is_standard_kalman<StandardKalman<Fmt, S, kF>> : std::true_type {};
/// True for the half Kalman filter.
template <typename T>
struct is_half_kalman : std::false_type {};
/// True for the half Kalman filter.
template <typename Fmt, typename S, typename D, CovarianceUpdate kF>
struct is_half_kalman<HalfKalman<Fmt, S, D, kF>> : std::true_type {};

/// The filter core's estimate of a Kalman estimator copy set to x (P kept): through the
/// protected core, on a probe derived from it and sliced back.
template <typename Est>
void set_core_estimate(Est& e, const typename Est::StateVec& x) {
  struct Probe : Est {
    explicit Probe(const Est& b) : Est(b) {}
    void set(const typename Est::StateVec& v) { this->core_.reset(v, this->core_.covariance()); }
  };
  Probe p(e);
  p.set(x);
  e = p;
}

/// x̂ of the standard Kalman filter: its core's estimate.
template <typename Fmt, typename S, CovarianceUpdate kF>
typename StandardKalman<Fmt, S, kF>::StateVec memory_estimate(const StandardKalman<Fmt, S, kF>& e) {
  return e.core().state();
}
/// x̂ of the half Kalman filter: its core's estimate (the prediction to t_k).
template <typename Fmt, typename S, typename D, CovarianceUpdate kF>
typename HalfKalman<Fmt, S, D, kF>::StateVec memory_estimate(const HalfKalman<Fmt, S, D, kF>& e) {
  return e.core().state();
}
/// x̂ of the complete Kalman filter: its core's estimate at the last sample (not the prediction).
template <typename Fmt, typename S, typename D, CovarianceUpdate kF>
typename CompleteKalman<Fmt, S, D, kF>::StateVec memory_estimate(const CompleteKalman<Fmt, S, D, kF>& e) {
  return e.core().state();
}
/// x̂ of the deadbeat observer.
template <typename Fmt, typename S>
typename DeadbeatObserver<Fmt, S>::StateVec memory_estimate(const DeadbeatObserver<Fmt, S>& e) {
  return e.prediction();
}

/// Standard and half Kalman: x̂ and u_last (u_prev unused).
template <typename Est, typename Design>
auto set_memory(Est& e, const Design&, const typename Est::StateVec& x, const typename Est::InputVec& u_last,
                const typename Est::InputVec&, bool)
    -> std::enable_if_t<is_standard_kalman<Est>::value || is_half_kalman<Est>::value> {
  set_core_estimate(e, x);
  e.set_applied_input(u_last);
}
/// Complete Kalman: x̂, then the input history [u_prev from the sample, u_last from t_k]
/// (two set_applied_input calls: the second moves the first to the earlier slot).
template <typename Fmt, typename S, typename D, CovarianceUpdate kF, typename Design>
void set_memory(CompleteKalman<Fmt, S, D, kF>& e, const Design&,
                const Vector<typename Fmt::State, S::kStates>& x, const Vector<typename Fmt::Input, S::kInputs>& u_last,
                const Vector<typename Fmt::Input, S::kInputs>& u_prev, bool) {
  set_core_estimate(e, x);
  e.set_applied_input(u_prev);
  e.set_applied_input(u_last);
}
/// Deadbeat observer: its members are private and reset() marks the next job as the first
/// (no prediction). Before the first job x̂ is set as it is; after it, to the observer's own
/// prediction Φ(h) x̂ + Γ(h) u_last (the same affine() call its update makes), so that the
/// first-job path (correction only) computes what the later-job path would.
template <typename Fmt, typename S, typename Design>
void set_memory(DeadbeatObserver<Fmt, S>& e, const Design& d,
                const Vector<typename Fmt::State, S::kStates>& x, const Vector<typename Fmt::Input, S::kInputs>& u_last,
                const Vector<typename Fmt::Input, S::kInputs>&, bool first_job) {
  using Cov = typename DeadbeatObserver<Fmt, S>::Cov;
  const auto start = first_job ? x
                               : affine<typename Fmt::State, typename S::PhiPattern, typename S::GammaPattern>(
                                     d.phi_h, x, d.gamma_h, u_last);
  e.reset(start, Cov{}, u_last);
}

}  // namespace oneshot::sim
