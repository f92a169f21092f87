/// @file sync_actuator_node.hpp
/// @brief The actuator of the actuation-synchronized loop: its timer fixes the actuation
///        instants t_k = t_{k−1} + h; right after each it asks the sensor for the next
///        sample (msg 1), echoing the input it really applied.
///
/// Commands (msg 3, seq = k) are buffered by the timer-mode ActuatorNode; at t_k the
/// command for k is applied, or, when it is late, the previous value is held and the miss
/// counted (late-command policy, brief §2). The request for k + 1 then carries the value
/// in force, so the controller predicts with the input the plant really got. Commands are
/// checked as in ActuatorNode (source, finite, range, timer window): a refused command is
/// counted and the last good value held.
#pragma once

#include <cstddef>
#include <cstdint>

#include "oneshot/hal/network_contract.hpp"
#include "oneshot/node/actuation_sync_messages.hpp"
#include "oneshot/node/actuator_node.hpp"

namespace oneshot::node {

/// Actuation-synchronized actuator of M inputs in scalar S on board `Board`.
template <typename Board, typename S, std::size_t M, std::size_t Slots = 8>
class SyncActuatorNode {
  static_assert(hal::kHasNetwork<Board>, "Board::Net must fulfil the network contract (network_contract.hpp)");

 public:
  /// Requests go to `sensor`; the input `initial` is in force from power-on.
  constexpr SyncActuatorNode(std::uint8_t sensor, const Vector<S, M>& initial)
      : sensor_(sensor), inner_(ActuatorMode::kOnTimer, initial) {}

  /// Frames waiting at the interface: commands are buffered until their instant.
  void on_receive() { inner_.on_receive(); }

  /// Accepts commands from `controller` only.
  constexpr void expect_source(std::uint8_t controller) { inner_.expect_source(controller); }
  /// Accepts commands in [u_min, u_max] only (the actuator's range from the design).
  constexpr void set_command_range(const Vector<S, M>& u_min, const Vector<S, M>& u_max) {
    inner_.set_command_range(u_min, u_max);
  }

  /// First timer interrupt (k = 0, no command exists yet): asks for sample 1, due at t_1.
  void start(McuInstant t_1) { request(1, t_1); }

  /// Timer interrupt at t_k (k ≥ 1): applies the command for k or holds the previous
  /// value (counted late), then asks for sample k + 1, due at t_next = t_k + h.
  void on_timer(SequenceNumber k, McuInstant t_next) {
    inner_.on_timer(k);
    request(k + 1, t_next);
  }

  /// True once after each newly applied command, with the value in `u`.
  constexpr bool take_output(Vector<S, M>& u) { return inner_.take_output(u); }
  /// The input in force (what the next request echoes).
  constexpr const Vector<S, M>& applied() const { return inner_.applied(); }
  /// Counters: applied commands, late periods (held value), refusals by cause, …
  constexpr const ActuatorStatistics& statistics() const { return inner_.statistics(); }
  /// Requests the interface refused.
  constexpr std::uint32_t refused() const { return requests_.refused; }
  /// Result of the last request send.
  [[nodiscard]] constexpr SendResult last_request() const { return last_request_; }
  /// Worst status of the frames the last on_receive() handled (kOk when none).
  [[nodiscard]] constexpr FrameStatus receive_status() const { return inner_.receive_status(); }

 private:
  void request(SequenceNumber k, McuInstant t_k) {
    ActuationRequest<S, M> r;
    r.k = k;
    r.t_k = t_k;
    r.u_applied = inner_.applied();
    last_request_ = send_message<Board>(sensor_, r, requests_);
  }

  std::uint8_t sensor_;
  ActuatorNode<Board, S, M, Slots> inner_;
  SendCounters requests_{};
  SendResult last_request_ = SendResult::kSent;
};

}  // namespace oneshot::node
