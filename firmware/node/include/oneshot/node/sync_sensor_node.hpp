/// @file sync_sensor_node.hpp
/// @brief The sensor of the actuation-synchronized loop: samples on the actuator's request
///        (at once, or late at t_k − D) and reports (k, y, τ_k = t_k − t_s) with the echo.
///
/// The board samples; the node says when. With late sampling (approach AKl) the sensor
/// waits until t_k − D, D the worst τ_sc + τ_c + τ_ca, so the prediction horizon is D
/// instead of h − τ_as; a request arriving after t_k − D is sampled at once.
/// Requests are untrusted (frame_checks.hpp): from another node than the expected actuator
/// (once set), with a non-finite or out-of-range echo, beyond the sequence window, or with
/// t_k more than the stamp window ahead of the sensor's clock (once set) they are refused
/// and counted; a restarted actuator (k from 0 again) is re-acquired on its R-th request.
#pragma once

#include <cstddef>
#include <cstdint>

#include "oneshot/hal/network_contract.hpp"
#include "oneshot/node/actuation_sync_messages.hpp"
#include "oneshot/node/frame_checks.hpp"

namespace oneshot::node {

/// Counters of a synchronized sensor (refusals by cause in the FrameRefusals part).
struct SyncSensorStatistics : FrameRefusals {
  std::uint32_t requests = 0;   ///< Requests decoded.
  std::uint32_t stale = 0;      ///< Requests not newer than the pending or last one (dropped).
  std::uint32_t malformed = 0;  ///< Frames that did not decode.
  std::uint32_t sends = 0;      ///< Reports sent.
  std::uint32_t refused = 0;    ///< Reports the interface refused.
};

/// Sensor of P outputs (echoing M inputs) in scalar S on board `Board`.
template <typename Board, typename S, std::size_t P, std::size_t M>
class SyncSensorNode {
  static_assert(hal::kHasNetwork<Board>, "Board::Net must fulfil the network contract (network_contract.hpp)");

 public:
  /// Reports go to `controller`; `late_us` = D (0: sample at once).
  constexpr SyncSensorNode(std::uint8_t controller, std::int32_t late_us) : controller_(controller), late_us_(late_us) {}

  /// Frames waiting at the interface. True when a sample is now due; `sample_at` is the
  /// instant to take it (now, or t_k − D when that is later).
  bool on_receive(McuInstant now, McuInstant& sample_at) {
    std::uint8_t bytes[kMaxMessageBytes];
    std::uint8_t source = 0;
    bool due = false;
    for (std::size_t n = Board::Net::receive(source, bytes, sizeof bytes); n != 0;
         n = Board::Net::receive(source, bytes, sizeof bytes)) {
      ActuationRequest<S, M> r;
      if (!decode(bytes, n, r)) {
        ++stats_.malformed;
        continue;
      }
      ++stats_.requests;
      if (!source_.check(source, stats_) || !check_payload(r.u_applied, echo_range_, stats_)) continue;
      if (lead_us_ >= 0 && r.t_k - now > lead_us_) {  // t_k too far ahead of the sensor's clock
        ++stats_.refused_sequence;
        continue;
      }
      const SequenceVerdict v = gate_.offer(r.k);
      if (v == SequenceVerdict::kStale) ++stats_.stale;
      if (!count_sequence(v, stats_)) continue;
      pending_ = r;
      have_pending_ = true;
      due = true;
    }
    if (!due) return false;
    sample_at = now;
    if (late_us_ > 0) {
      const McuInstant late = pending_.t_k.plus(-late_us_);
      if (earlier(now, late)) sample_at = late;
    }
    return true;
  }

  /// The sample y taken at `now` for the pending request: reports it (false when none).
  bool on_sample(McuInstant now, const Vector<S, P>& y) {
    if (!have_pending_) return false;
    have_pending_ = false;
    SampleReport<S, P, M> m;
    m.k = pending_.k;
    m.t_s = now;
    m.tau_us = static_cast<std::int32_t>(pending_.t_k - now);
    m.y = y;
    m.u_applied = pending_.u_applied;
    std::uint8_t bytes[kMaxMessageBytes];
    const std::size_t n = encode(m, bytes);
    if (Board::Net::send(controller_, bytes, n)) {
      ++stats_.sends;
    } else {
      ++stats_.refused;
    }
    return true;
  }

  /// Accepts requests from `actuator` only.
  constexpr void expect_source(std::uint8_t actuator) { source_.set(actuator); }
  /// Accepts echoes in [u_min, u_max] only (the actuator's range from the design).
  constexpr void set_echo_range(const Vector<S, M>& u_min, const Vector<S, M>& u_max) {
    echo_range_ = ValueRange<S, M>(u_min, u_max);
  }
  /// Refuses requests whose t_k is more than `lead_us` ≥ 0 ahead of the sensor's clock
  /// (a request is sent one period h before its t_k: a few h is the documented window).
  constexpr void set_stamp_window(std::int32_t lead_us) { lead_us_ = lead_us; }
  /// Sequence window W and re-acquisition count R (frame_checks.hpp).
  constexpr void set_sequence_window(std::uint32_t window, std::uint32_t reacquire) {
    gate_ = SequenceGate(window, reacquire);
  }

  /// Counters.
  constexpr const SyncSensorStatistics& statistics() const { return stats_; }

 private:
  std::uint8_t controller_;
  std::int32_t late_us_;
  ActuationRequest<S, M> pending_{};
  bool have_pending_ = false;
  std::int32_t lead_us_ = -1;  // < 0: t_k unchecked
  SequenceGate gate_{};
  ExpectedSource source_{};
  ValueRange<S, M> echo_range_{};
  SyncSensorStatistics stats_{};
};

}  // namespace oneshot::node
