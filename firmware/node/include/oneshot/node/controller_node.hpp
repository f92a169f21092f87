/// @file controller_node.hpp
/// @brief A controller node: keeps the newest measurement, runs its control law on each
///        arrival or on its own timer, and sends time-stamped commands.
///
/// The law is a plug-in with
///     bool compute(const Message<VectorPayload<S, P>>& latest, bool fresh, McuInstant now, Vector<S, M>& u)
/// (fresh: a measurement arrived since the last computation); it returns true to send u.
/// A command carries the sequence number of the measurement it was computed from, so an
/// actuator can match it to its period; older or repeated measurements are counted and
/// dropped (reordering on the network never moves the estimate back in time). Measurements
/// that are not finite, outside the sensor's range (once set), from another node than the
/// expected sensor (once set) or beyond the sequence window are refused and counted; a
/// restarted sensor is re-acquired on its R-th frame (frame_checks.hpp).
#pragma once

#include <cstddef>
#include <cstdint>

#include "oneshot/hal/network_contract.hpp"
#include "oneshot/matrix.hpp"
#include "oneshot/node/frame_checks.hpp"
#include "oneshot/node/message.hpp"

namespace oneshot::node {

/// When the controller computes.
enum class ControllerMode : std::uint8_t {
  kOnArrival,  ///< On every newer measurement.
  kOnTimer,    ///< On its timer (on_timer), with the newest measurement.
};

/// Counters of a controller node (refusals by cause in the FrameRefusals part).
struct ControllerStatistics : FrameRefusals {
  std::uint32_t received = 0;      ///< Measurements decoded.
  std::uint32_t stale = 0;         ///< Older than or equal to the newest one (dropped).
  std::uint32_t malformed = 0;     ///< Frames that did not decode.
  std::uint32_t computations = 0;  ///< Law runs.
  std::uint32_t withheld = 0;      ///< Commands not sent: the law gave a non-finite value.
  std::uint32_t sends = 0;         ///< Commands sent.
  std::uint32_t refused = 0;       ///< Sends the interface refused.
};

/// Controller from P measured outputs to M commands in scalar S, on board `Board`.
template <typename Board, typename Law, typename S, std::size_t P, std::size_t M>
class ControllerNode {
  static_assert(hal::kHasNetwork<Board>, "Board::Net must fulfil the network contract (network_contract.hpp)");

 public:
  using Measurement = Message<VectorPayload<S, P>>;  ///< What it receives.
  using Command = Message<VectorPayload<S, M>>;      ///< What it sends.

  /// Sends commands to `destination`, computing per `mode` with `law`.
  constexpr ControllerNode(std::uint8_t destination, ControllerMode mode, const Law& law)
      : destination_(destination), mode_(mode), law_(law) {}

  /// Frames waiting at the interface: decodes them; on-arrival mode computes for each newer one.
  void on_receive(McuInstant now) {
    std::uint8_t bytes[kMaxMessageBytes];
    std::uint8_t source = 0;
    for (std::size_t n = Board::Net::receive(source, bytes, sizeof bytes); n != 0;
         n = Board::Net::receive(source, bytes, sizeof bytes)) {
      Measurement m;
      if (!decode(bytes, n, m)) {
        ++stats_.malformed;
        continue;
      }
      ++stats_.received;
      if (!source_.check(source, stats_) || !check_payload(m.payload.value, range_, stats_)) continue;
      const SequenceVerdict v = gate_.offer(m.seq);
      if (v == SequenceVerdict::kStale) ++stats_.stale;
      if (!count_sequence(v, stats_)) continue;
      latest_ = m;
      have_ = true;
      fresh_ = true;
      if (mode_ == ControllerMode::kOnArrival) run(now);
    }
  }

  /// The controller's timer: timer mode computes with the newest measurement.
  void on_timer(McuInstant now) {
    if (mode_ == ControllerMode::kOnTimer && have_) run(now);
  }

  /// Accepts measurements from `sensor` only.
  constexpr void expect_source(std::uint8_t sensor) { source_.set(sensor); }
  /// Accepts measurements in [y_min, y_max] only (the sensor's range from the design).
  constexpr void set_measurement_range(const Vector<S, P>& y_min, const Vector<S, P>& y_max) {
    range_ = ValueRange<S, P>(y_min, y_max);
  }
  /// Sequence window W and re-acquisition count R (frame_checks.hpp).
  constexpr void set_sequence_window(std::uint32_t window, std::uint32_t reacquire) {
    gate_ = SequenceGate(window, reacquire);
  }

  /// The law (its estimator state, …).
  constexpr Law& law() { return law_; }
  /// Newest measurement (valid once one arrived).
  constexpr const Measurement& latest() const { return latest_; }
  /// Counters.
  constexpr const ControllerStatistics& statistics() const { return stats_; }

 private:
  void run(McuInstant now) {
    ++stats_.computations;
    Command c;
    const bool send = law_.compute(latest_, fresh_, now, c.payload.value);
    fresh_ = false;
    if (!send) return;
    if (!all_finite(c.payload.value)) {
      ++stats_.withheld;
      return;
    }
    c.seq = latest_.seq;
    c.stamp = now;
    std::uint8_t bytes[kMaxMessageBytes];
    const std::size_t n = encode(c, bytes);
    if (Board::Net::send(destination_, bytes, n)) {
      ++stats_.sends;
    } else {
      ++stats_.refused;
    }
  }

  std::uint8_t destination_;
  ControllerMode mode_;
  Law law_;
  Measurement latest_{};
  bool have_ = false;
  bool fresh_ = false;
  SequenceGate gate_{};
  ExpectedSource source_{};
  ValueRange<S, P> range_{};
  ControllerStatistics stats_{};
};

}  // namespace oneshot::node
