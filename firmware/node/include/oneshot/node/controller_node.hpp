/// @file controller_node.hpp
/// @brief A controller node: keeps the newest measurement, runs its control law on each
///        arrival or on its own timer, and sends time-stamped commands.
///
/// The law is a plug-in with
///     LawResult compute(const Message<VectorPayload<S, P>>& latest, bool fresh, McuInstant now, Vector<S, M>& u)
/// (fresh: a measurement arrived since the last computation); it returns kSend to send u.
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
#include "oneshot/node/frame_io.hpp"
#include "oneshot/node/law_result.hpp"
#include "oneshot/node/message.hpp"

namespace oneshot::node {

/// When the controller computes.
enum class ControllerMode : std::uint8_t {
  kOnArrival,  ///< On every newer measurement.
  kOnTimer,    ///< On its timer (on_timer), with the newest measurement.
};

/// Counters of a controller node (drops and refusals by cause in the FrameRefusals part,
/// commands sent or refused by the interface in the SendCounters part).
struct ControllerStatistics : FrameRefusals, SendCounters {
  std::uint32_t received = 0;      ///< Measurements decoded.
  std::uint32_t computations = 0;  ///< Law runs.
  std::uint32_t withheld = 0;      ///< Commands not sent: the law gave a non-finite value.
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

  /// Frames waiting at the interface: each one through on_frame().
  void on_receive(McuInstant now) {
    receive_status_ = drain_frames<Board>(
        [&](std::uint8_t source, const std::uint8_t* bytes, std::size_t size) { return on_frame(source, bytes, size, now); });
  }

  /// One frame from `source`: a measurement newer than the newest one is kept (on-arrival mode
  /// computes); its status, counted by cause in statistics().
  [[nodiscard]] FrameStatus on_frame(std::uint8_t source, const std::uint8_t* bytes, std::size_t size, McuInstant now) {
    return admit_frame<Measurement>(source, bytes, size, stats_.received, stats_, [&](const Measurement& m, std::uint8_t src) {
      const FrameStatus s = then_check(then_check(source_.check(src), [&] { return check_payload(m.payload.value, range_); }),
                                       [&] { return frame_status(gate_.offer(m.seq)); });
      if (!accepted(s)) return s;
      latest_ = m;
      have_ = true;
      fresh_ = true;
      if (mode_ == ControllerMode::kOnArrival) run(now, latest_.seq);
      return s;
    });
  }

  /// The controller's timer: timer mode computes with the newest measurement.
  void on_timer(McuInstant now) {
    if (mode_ == ControllerMode::kOnTimer && have_) run(now, latest_.seq);
  }

  /// The controller's timer in a loop whose commands name the period they are for (a one-shot
  /// loop: computed in period k, applied at k + 1 by an actuator on its timer): timer mode
  /// computes with the newest measurement and stamps the command `command_seq`.
  void on_timer(McuInstant now, SequenceNumber command_seq) {
    if (mode_ == ControllerMode::kOnTimer && have_) run(now, command_seq);
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
  /// Worst status of the frames the last on_receive() handled (kOk when none).
  [[nodiscard]] constexpr FrameStatus receive_status() const { return receive_status_; }
  /// Result of the last command send (counted in statistics()).
  [[nodiscard]] constexpr SendResult last_send() const { return last_send_; }

 private:
  void run(McuInstant now, SequenceNumber command_seq) {
    ++stats_.computations;
    Command c;
    const LawResult result = law_.compute(latest_, fresh_, now, c.payload.value);
    fresh_ = false;
    if (result != LawResult::kSend) return;
    if (!all_finite(c.payload.value)) {
      ++stats_.withheld;
      return;
    }
    c.seq = command_seq;
    c.stamp = now;
    last_send_ = send_message<Board>(destination_, c, stats_);
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
  FrameStatus receive_status_ = FrameStatus::kOk;
  SendResult last_send_ = SendResult::kSent;
};

}  // namespace oneshot::node
