/// @file actuator_node.hpp
/// @brief An actuator node: applies commands on arrival, or on its timer from a buffer of
///        commands keyed by sequence number, holding the last value when a command is late.
///
/// On arrival: a command newer than the one applied (sequence window with re-acquisition,
/// frame_checks.hpp) is applied at once; older ones are counted and dropped. On the timer
/// of period k: the command stamped k is applied when it is in the buffer; otherwise the
/// previous value is held and the miss counted (the late-command policy of the
/// networked-actuation brief). Timer mode buffers only commands for the next Slots periods
/// after the last timer (k_t, k_t + Slots], k_t = 0 before the first: the actuator's own
/// period count is the reference, so a forged or restarted sequence never blocks a slot.
/// A command that is not finite, outside [u_min, u_max] (once set) or from another node
/// than the expected controller (once set) is refused and counted: the last good value
/// stays applied. The glue writes the value to the output stage after take_output()
/// reports a new one.
#pragma once

#include <cstddef>
#include <cstdint>

#include "oneshot/hal/network_contract.hpp"
#include "oneshot/matrix.hpp"
#include "oneshot/node/command_buffer.hpp"
#include "oneshot/node/frame_checks.hpp"
#include "oneshot/node/frame_io.hpp"
#include "oneshot/node/message.hpp"

namespace oneshot::node {

/// When the actuator applies a command.
enum class ActuatorMode : std::uint8_t {
  kOnArrival,  ///< As soon as a newer command arrives.
  kOnTimer,    ///< At its timer, the command stamped with the timer's period.
};

/// Counters of an actuator node (drops and refusals by cause in the FrameRefusals part; stale:
/// not newer than the applied one, or its period already past).
struct ActuatorStatistics : FrameRefusals {
  std::uint32_t received = 0;   ///< Commands decoded.
  std::uint32_t applied = 0;    ///< Commands applied.
  std::uint32_t late = 0;       ///< Timer: no command for the period (previous value held).
};

/// Actuator of M inputs in scalar S on board `Board`; `Slots` buffered commands.
template <typename Board, typename S, std::size_t M, std::size_t Slots = 8>
class ActuatorNode {
  static_assert(hal::kHasNetwork<Board>, "Board::Net must fulfil the network contract (network_contract.hpp)");

 public:
  using Command = Message<VectorPayload<S, M>>;  ///< What it receives.

  /// Actuator in `mode` starting from the input `initial`.
  constexpr ActuatorNode(ActuatorMode mode, const Vector<S, M>& initial) : mode_(mode), applied_(initial) {}

  /// Frames waiting at the interface: each one through on_frame().
  void on_receive() {
    receive_status_ = drain_frames<Board>(
        [&](std::uint8_t source, const std::uint8_t* bytes, std::size_t size) { return on_frame(source, bytes, size); });
  }

  /// One frame from `source`: a command is buffered (timer mode) or applied at once (on-arrival
  /// mode); its status, counted by cause in statistics().
  [[nodiscard]] FrameStatus on_frame(std::uint8_t source, const std::uint8_t* bytes, std::size_t size) {
    return admit_frame<Command>(source, bytes, size, stats_.received, stats_, [&](const Command& c, std::uint8_t src) {
      const FrameStatus s = then_check(source_.check(src), [&] { return check_payload(c.payload.value, range_); });
      if (s != FrameStatus::kOk) return s;
      if (mode_ == ActuatorMode::kOnTimer) return buffer_command(c);
      const FrameStatus v = frame_status(gate_.offer(c.seq));
      if (accepted(v)) apply(c.seq, c.payload.value);
      return v;
    });
  }

  /// The timer of period k (timer mode): applies the command stamped k, or holds.
  void on_timer(SequenceNumber k) {
    if (mode_ != ActuatorMode::kOnTimer) return;
    timer_k_ = k;
    Vector<S, M> u;
    if (buffer_.find(k, u)) {
      apply(k, u);
    } else {
      ++stats_.late;
    }
  }

  /// Accepts commands from `controller` only.
  constexpr void expect_source(std::uint8_t controller) { source_.set(controller); }
  /// Accepts commands in [u_min, u_max] only (the actuator's range from the design).
  constexpr void set_command_range(const Vector<S, M>& u_min, const Vector<S, M>& u_max) {
    range_ = ValueRange<S, M>(u_min, u_max);
  }
  /// On-arrival mode: sequence window W and re-acquisition count R (frame_checks.hpp).
  constexpr void set_sequence_window(std::uint32_t window, std::uint32_t reacquire) {
    gate_ = SequenceGate(window, reacquire);
  }

  /// True once after each newly applied command, with the value to output in `u`.
  constexpr bool take_output(Vector<S, M>& u) {
    if (!new_output_) return false;
    u = applied_;
    new_output_ = false;
    return true;
  }
  /// The input in force (the echo a loop may send back).
  constexpr const Vector<S, M>& applied() const { return applied_; }
  /// Sequence number of the command in force (valid after the first).
  constexpr SequenceNumber applied_seq() const { return applied_seq_; }
  /// Counters.
  constexpr const ActuatorStatistics& statistics() const { return stats_; }
  /// Worst status of the frames the last on_receive() handled (kOk when none).
  [[nodiscard]] constexpr FrameStatus receive_status() const { return receive_status_; }

 private:
  // Timer mode, d = seq − k_t: 1 … Slots waits in the buffer; ≤ 0 is late (stale); beyond is refused.
  [[nodiscard]] constexpr FrameStatus buffer_command(const Command& c) {
    const SequenceNumber d = c.seq - timer_k_;
    if (!seq_newer(c.seq, timer_k_)) return FrameStatus::kStale;
    if (d > Slots) return FrameStatus::kRefusedSequence;
    buffer_.replace(c.seq, c.payload.value);
    return FrameStatus::kOk;
  }

  constexpr void apply(SequenceNumber seq, const Vector<S, M>& u) {
    applied_ = u;
    applied_seq_ = seq;
    any_applied_ = true;
    new_output_ = true;
    ++stats_.applied;
  }

  ActuatorMode mode_;
  Vector<S, M> applied_;
  SequenceNumber applied_seq_ = 0;
  bool any_applied_ = false;
  bool new_output_ = false;
  SequenceNumber timer_k_ = 0;
  SequenceGate gate_{};
  ExpectedSource source_{};
  ValueRange<S, M> range_{};
  CommandBuffer<S, M, Slots> buffer_{};
  ActuatorStatistics stats_{};
  FrameStatus receive_status_ = FrameStatus::kOk;
};

}  // namespace oneshot::node
