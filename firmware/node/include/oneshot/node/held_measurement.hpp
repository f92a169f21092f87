/// @file held_measurement.hpp
/// @brief The receiver of send-on-delta nodes: last value and step per node, the dropout
///        detector, and the measurement and variance R̄ the estimator uses at every step
///        (send-on-delta brief §4).
///
/// Node i's packet at step k:          z_i = y_i,k,   R̄_ii = R_ii
/// no packet (held value, kHeld):      z_i = y_rx,i,  R̄_ii = R_ii + ((d_i + 1) δy,i)² / 3
/// no packet (kPredictOnly):           no correction for node i
/// The held value's error Δ_i = y_i − y_rx,i is taken as uniform on ±(d_i + 1) δy,i, hence
/// the variance ((d_i + 1) δy,i)²/3; d_i comes from the DropoutDetector (0 for plain SOD).
/// Before a node's first arrival there is nothing to hold: no correction. A packet whose
/// value is not finite is refused and counted (the held value stays the last good one).
#pragma once

#include <cstddef>
#include <cstdint>

#include "oneshot/matrix.hpp"
#include "oneshot/node/dropout_detector.hpp"
#include "oneshot/node/frame_checks.hpp"
#include "oneshot/node/message.hpp"
#include "oneshot/scalar_traits.hpp"

namespace oneshot::node {

/// What the receiver does for a node that sent nothing (or whose packet was lost).
enum class SilencePolicy : std::uint8_t {
  kHeld,         ///< Correct with the held value and the inflated variance R̄.
  kPredictOnly,  ///< Skip the correction (a Kalman filter that only predicts).
};

/// One node's measurement for the estimator at step k.
template <typename S>
struct HeldMeasurement {
  bool present = false;   ///< Correct with it (false: predict only for this node).
  bool arrived = false;   ///< A packet arrived at this step.
  S z{};                  ///< Value used (the new sample or the held one).
  S r_bar{};              ///< Its variance R̄_ii.
  std::uint32_t dropouts = 0;  ///< d_i (0 when a packet arrived).
};

/// Receiver of P scalar send-on-delta nodes (node i measures output i).
template <typename S, std::size_t P>
class HeldMeasurementReceiver {
  static_assert(kIsFloating<S>, "the held-value variance needs a floating format");

 public:
  /// Thresholds δy, measurement variances R_ii, time rules n_t (0: plain SOD) and the policy.
  constexpr HeldMeasurementReceiver(const Vector<S, P>& delta_y, const Vector<S, P>& r_diag,
                                    const std::uint32_t (&n_t)[P], SilencePolicy policy)
      : delta_y_(delta_y), r_(r_diag), policy_(policy) {
    for (std::size_t i = 0; i < P; ++i) detector_[i] = DropoutDetector(n_t[i]);
  }

  /// Node i's packet of sample k with value y arrived (call before measurement(i, k)).
  /// kRefusedNonFinite (counted, nothing changed) when y is not finite, else kOk.
  [[nodiscard]] constexpr FrameStatus on_packet(std::size_t i, SequenceNumber k, S y) {
    if (!is_finite(y)) return count_frame(FrameStatus::kRefusedNonFinite, refusals_);
    y_rx_[i] = y;
    detector_[i].on_receive(k);
    arrived_k_[i] = k;
    arrived_[i] = true;
    return FrameStatus::kOk;
  }
  /// Node i's measurement at step k: the packet that arrived at k, else the held value with
  /// R̄_ii = R_ii + ((d + 1) δy)²/3 (kHeld) or nothing (kPredictOnly).
  constexpr HeldMeasurement<S> measurement(std::size_t i, SequenceNumber k) const {
    using T = ScalarTraits<S>;
    HeldMeasurement<S> m;
    if (arrived_[i] && arrived_k_[i] == k) {
      m.present = true;
      m.arrived = true;
      m.z = y_rx_[i];
      m.r_bar = r_[i];
      return m;
    }
    if (!detector_[i].any_received()) return m;
    m.dropouts = detector_[i].dropouts(k);
    if (policy_ == SilencePolicy::kPredictOnly) return m;
    // ((d + 1) δy)² / 3: variance of a uniform error on ±(d + 1) δy.
    const S width = (T::from_double(static_cast<double>(m.dropouts)) + T::one()) * delta_y_[i];
    m.present = true;
    m.z = y_rx_[i];
    m.r_bar = r_[i] + width * width / T::from_int(3);
    return m;
  }
  /// Packets refused, by cause.
  constexpr const FrameRefusals& refusals() const { return refusals_; }
  /// Node i's detector.
  constexpr const DropoutDetector& detector(std::size_t i) const { return detector_[i]; }

 private:
  Vector<S, P> delta_y_;
  Vector<S, P> r_;
  SilencePolicy policy_;
  DropoutDetector detector_[P];
  Vector<S, P> y_rx_{};
  SequenceNumber arrived_k_[P] = {};
  bool arrived_[P] = {};
  FrameRefusals refusals_{};
};

}  // namespace oneshot::node
