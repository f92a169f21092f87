/// @file actuator_node.hpp
/// @brief An actuator node: applies commands on arrival, or on its timer from a buffer of
///        commands keyed by sequence number, holding the last value when a command is late.
///
/// On arrival: a command newer than the one applied is applied at once; older ones are
/// counted and dropped. On the timer of period k: the command stamped k is applied when
/// it is in the buffer; otherwise the previous value is held and the miss counted (the
/// late-command policy of the networked-actuation brief). The glue writes the value to
/// the output stage after take_output() reports a new one.
#pragma once

#include <cstddef>
#include <cstdint>

#include "oneshot/hal/network_contract.hpp"
#include "oneshot/matrix.hpp"
#include "oneshot/node/command_buffer.hpp"
#include "oneshot/node/message.hpp"

namespace oneshot::node {

/// When the actuator applies a command.
enum class ActuatorMode : std::uint8_t {
  kOnArrival,  ///< As soon as a newer command arrives.
  kOnTimer,    ///< At its timer, the command stamped with the timer's period.
};

/// Counters of an actuator node.
struct ActuatorStatistics {
  std::uint32_t received = 0;   ///< Commands decoded.
  std::uint32_t stale = 0;      ///< On arrival: not newer than the applied one (dropped).
  std::uint32_t malformed = 0;  ///< Frames that did not decode.
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

  /// Frames waiting at the interface: buffered, and applied at once in on-arrival mode.
  void on_receive() {
    std::uint8_t bytes[kMaxMessageBytes];
    std::uint8_t source = 0;
    for (std::size_t n = Board::Net::receive(source, bytes, sizeof bytes); n != 0;
         n = Board::Net::receive(source, bytes, sizeof bytes)) {
      Command c;
      if (!decode(bytes, n, c)) {
        ++stats_.malformed;
        continue;
      }
      ++stats_.received;
      if (mode_ == ActuatorMode::kOnTimer) {
        buffer_.store(c.seq, c.payload.value);
        continue;
      }
      if (any_applied_ && !seq_newer(c.seq, applied_seq_)) {
        ++stats_.stale;
        continue;
      }
      apply(c.seq, c.payload.value);
    }
  }

  /// The timer of period k (timer mode): applies the command stamped k, or holds.
  void on_timer(SequenceNumber k) {
    if (mode_ != ActuatorMode::kOnTimer) return;
    Vector<S, M> u;
    if (buffer_.find(k, u)) {
      apply(k, u);
    } else {
      ++stats_.late;
    }
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

 private:
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
  CommandBuffer<S, M, Slots> buffer_{};
  ActuatorStatistics stats_{};
};

}  // namespace oneshot::node
