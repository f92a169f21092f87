/// @file sensor_node.hpp
/// @brief A sensor node: samples on its timer or on request, decides with its trigger rule
///        (time-triggered or event-triggered) and sends time-stamped samples.
///
/// The rule is a plug-in (PeriodicTrigger, SendOnDeltaTrigger, MtmTrigger or any class
/// with evaluate(k, y) → SendCause and on_sent(k, y)). The sample index k is the message's
/// sequence number, so a receiver sees which samples it missed; the stamp is the node's
/// clock at the sample.
#pragma once

#include <cstddef>
#include <cstdint>

#include "oneshot/hal/network_contract.hpp"
#include "oneshot/matrix.hpp"
#include "oneshot/node/frame_io.hpp"
#include "oneshot/node/message.hpp"
#include "oneshot/node/send_cause.hpp"

namespace oneshot::node {

/// Counters of a sensor node (messages sent or refused by the interface in the SendCounters part).
struct SensorStatistics : SendCounters {
  std::uint32_t samples = 0;        ///< Samples evaluated.
  std::uint32_t by_cause[6] = {};   ///< Sends per SendCause (index = cause).
};

/// Sensor of P outputs in scalar S on board `Board`, rule `Trigger`.
template <typename Board, typename Trigger, typename S, std::size_t P>
class SensorNode {
  static_assert(hal::kHasNetwork<Board>, "Board::Net must fulfil the network contract (network_contract.hpp)");

 public:
  /// Sends to `destination` under `trigger`.
  constexpr SensorNode(std::uint8_t destination, const Trigger& trigger) : destination_(destination), trigger_(trigger) {}

  /// Sample k taken at `now` with value y: sends when the rule fires; returns the cause.
  SendCause on_sample(SequenceNumber k, McuInstant now, const Vector<S, P>& y) {
    ++stats_.samples;
    const SendCause cause = trigger_.evaluate(k, y);
    if (cause == SendCause::kNone) return cause;
    Message<VectorPayload<S, P>> m;
    m.seq = k;
    m.stamp = now;
    m.payload.value = y;
    if (send_message<Board>(destination_, m, stats_) == SendResult::kSent) ++stats_.by_cause[static_cast<std::size_t>(cause)];
    trigger_.on_sent(k, y);  // no acknowledgement: the sender remembers what it tried to send
    return cause;
  }

  /// The rule (e.g. to notify a reference change).
  constexpr Trigger& trigger() { return trigger_; }
  /// Counters.
  constexpr const SensorStatistics& statistics() const { return stats_; }

 private:
  std::uint8_t destination_;
  Trigger trigger_;
  SensorStatistics stats_{};
};

}  // namespace oneshot::node
