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
#include "oneshot/node/frame_io.hpp"

namespace oneshot::node {

/// Counters of a synchronized sensor (drops and refusals by cause in the FrameRefusals part,
/// reports sent or refused by the interface in the SendCounters part).
struct SyncSensorStatistics : FrameRefusals, SendCounters {
  std::uint32_t requests = 0;   ///< Requests decoded.
};

/// Outcome of SyncSensorNode::on_sample().
enum class [[nodiscard]] ReportResult : std::uint8_t {
  kSent,       ///< The report was handed to the interface.
  kRefused,    ///< The interface refused the report (counted).
  kNoRequest,  ///< No request was pending: nothing reported.
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
    bool due = false;
    receive_status_ = drain_frames<Board>([&](std::uint8_t source, const std::uint8_t* bytes, std::size_t size) {
      const FrameStatus s = on_frame(source, bytes, size, now);
      due = due || accepted(s);
      return s;
    });
    if (!due) return false;
    sample_at = now;
    if (late_us_ > 0) {
      const McuInstant late = pending_.t_k.plus(-late_us_);
      if (earlier(now, late)) sample_at = late;
    }
    return true;
  }

  /// One frame from `source` at `now`: an accepted request becomes the pending one; its
  /// status, counted by cause in statistics().
  [[nodiscard]] FrameStatus on_frame(std::uint8_t source, const std::uint8_t* bytes, std::size_t size, McuInstant now) {
    using Request = ActuationRequest<S, M>;
    return admit_frame<Request>(source, bytes, size, stats_.requests, stats_, [&](const Request& r, std::uint8_t src) {
      FrameStatus s = then_check(source_.check(src), [&] { return check_payload(r.u_applied, echo_range_); });
      // t_k too far ahead of the sensor's clock: refused as a stamp outside its window.
      if (s == FrameStatus::kOk && lead_us_ >= 0 && r.t_k - now > lead_us_) s = FrameStatus::kRefusedSequence;
      s = then_check(s, [&] { return frame_status(gate_.offer(r.k)); });
      if (accepted(s)) {
        pending_ = r;
        have_pending_ = true;
      }
      return s;
    });
  }

  /// The sample y taken at `now` for the pending request: reports it (kNoRequest when none).
  [[nodiscard]] ReportResult on_sample(McuInstant now, const Vector<S, P>& y) {
    if (!have_pending_) return ReportResult::kNoRequest;
    have_pending_ = false;
    SampleReport<S, P, M> m;
    m.k = pending_.k;
    m.t_s = now;
    m.tau_us = static_cast<std::int32_t>(pending_.t_k - now);
    m.y = y;
    m.u_applied = pending_.u_applied;
    return send_message<Board>(controller_, m, stats_) == SendResult::kSent ? ReportResult::kSent : ReportResult::kRefused;
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
  /// Worst status of the frames the last on_receive() handled (kOk when none).
  [[nodiscard]] constexpr FrameStatus receive_status() const { return receive_status_; }

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
  FrameStatus receive_status_ = FrameStatus::kOk;
};

}  // namespace oneshot::node
