/// @file sync_controller_node.hpp
/// @brief The controller of the actuation-synchronized loop: on each sample report it runs
///        its estimator to the actuation instant t_k and sends u_k for period k.
///
///     x̂_k = estimator(τ_k, y_s,k, u applied at t_{k−1}),   u_k = u_ref,k − L (x̂_k − x_ref,k),
/// clamped to the actuator's range (counted). The estimator is a plug-in (sync_estimators.hpp);
/// the reference gives x_ref,k and u_ref,k for the instant the command targets. Reports
/// that are not newer than the last one are counted and dropped. Reports are untrusted
/// (frame_checks.hpp): from another node than the expected sensor (once set), with a
/// non-finite y or echo, y, echo or τ outside their ranges (once set), or beyond the
/// sequence window they are refused and counted; a restarted actuator's new k is
/// re-acquired on the R-th report. The estimator never leaves a non-finite estimate (its
/// update() resets it and returns Status::kNonFinite, counted): no command is sent then,
/// and a command that is not finite is never sent (the actuator holds its value).
///
/// Periods without a report (lost, refused, or while a restarted peer is re-acquired) are
/// predicted over once the period h is set (set_period_us()): with t_k = t_s,k + τ_k the
/// actuation instant a report targets (sensor clock, independent of k), a report whose t_k
/// is n = round((t_k − t_last)/h) ≥ 2 periods after the last one first runs
/// estimator.skip(u) for the n − 1 periods between (none when more than kMaxFilledPeriods:
/// a long silence), u the report's echo: the input the actuator held at t_k − h (its last
/// command that arrived, or what a restarted actuator applies; never a lost command). The
/// controller's own clock checks n: when the count of its receive instants differs by more
/// than one, the stamp is wrong and that count is taken. Without this the filter would take
/// the new sample as one period after the last and carry a period's drift for many periods.
/// The reference is read on the same time base (x_ref, u_ref at an index that moves by n
/// per report from the first report's k), not at the report's k: a restarted actuator's k
/// from 0 does not move the reference back to its start.
#pragma once

#include <cstddef>
#include <cstdint>

#include "oneshot/hal/network_contract.hpp"
#include "oneshot/node/actuation_sync_messages.hpp"
#include "oneshot/node/frame_checks.hpp"
#include "oneshot/node/frame_io.hpp"
#include "oneshot/node/square_wave_reference.hpp"
#include "oneshot/status.hpp"

namespace oneshot::node {

/// Counters of a synchronized controller (drops and refusals by cause in the FrameRefusals
/// part, commands sent or refused by the interface in the SendCounters part).
struct SyncControllerStatistics : FrameRefusals, SendCounters {
  std::uint32_t received = 0;      ///< Reports decoded.
  std::uint32_t computations = 0;  ///< Estimator runs.
  std::uint32_t faults = 0;        ///< Estimator runs whose status was not exact.
  std::uint32_t estimator_resets = 0;  ///< Estimator runs that turned non-finite (reset, no command).
  std::uint32_t withheld = 0;      ///< Commands not sent because they were not finite.
  std::uint32_t filled = 0;        ///< Periods without a report the estimator predicted over.
  std::uint32_t saturated = 0;     ///< Commands clamped to the actuator's range.
};

/// Most periods without a report one report fills in (more: none, the estimator's correction alone).
inline constexpr std::int32_t kMaxFilledPeriods = 64;

/// Controller of N states, P outputs, M inputs in scalar S on board `Board`.
template <typename Board, typename Estimator, typename Reference, typename S, std::size_t N, std::size_t P,
          std::size_t M>
class SyncControllerNode {
  static_assert(hal::kHasNetwork<Board>, "Board::Net must fulfil the network contract (network_contract.hpp)");

 public:
  using Report = SampleReport<S, P, M>;              ///< What it receives.
  using Command = Message<VectorPayload<S, M>>;      ///< What it sends (seq = k).

  /// Commands go to `actuator`; gain L, actuator range [u_min, u_max].
  constexpr SyncControllerNode(std::uint8_t actuator, const Matrix<S, M, N>& l, const Vector<S, M>& u_min,
                               const Vector<S, M>& u_max, const Estimator& estimator, const Reference& reference)
      : actuator_(actuator), l_(l), u_min_(u_min), u_max_(u_max), estimator_(estimator), reference_(reference) {}

  /// Frames waiting at the interface: each one through on_frame().
  void on_receive(McuInstant now) {
    receive_status_ = drain_frames<Board>(
        [&](std::uint8_t source, const std::uint8_t* bytes, std::size_t size) { return on_frame(source, bytes, size, now); });
  }

  /// One frame from `source`: a newer report gives one command; its status, counted by cause
  /// in statistics().
  [[nodiscard]] FrameStatus on_frame(std::uint8_t source, const std::uint8_t* bytes, std::size_t size, McuInstant now) {
    return admit_frame<Report>(source, bytes, size, stats_.received, stats_, [&](const Report& r, std::uint8_t src) {
      FrameStatus s = then_check(source_.check(src), [&] {
        return then_check(check_payload(r.y, y_range_), [&] { return check_payload(r.u_applied, echo_range_); });
      });
      if (s == FrameStatus::kOk && (r.tau_us < tau_min_us_ || r.tau_us > tau_max_us_)) s = FrameStatus::kRefusedOutOfRange;
      s = then_check(s, [&] { return frame_status(gate_.offer(r.k)); });
      if (accepted(s)) compute(r, now);
      return s;
    });
  }

  /// Accepts reports from `sensor` only.
  constexpr void expect_source(std::uint8_t sensor) { source_.set(sensor); }
  /// Accepts samples y in [y_min, y_max] only (the sensor's range from the design).
  constexpr void set_measurement_range(const Vector<S, P>& y_min, const Vector<S, P>& y_max) {
    y_range_ = ValueRange<S, P>(y_min, y_max);
  }
  /// Accepts echoes in the actuator's range [u_min, u_max] given at construction.
  constexpr void check_echo_range() { echo_range_ = ValueRange<S, M>(u_min_, u_max_); }
  /// Accepts τ_k in [tau_min_us, tau_max_us] only (the horizon the design covers).
  constexpr void set_tau_range(std::int32_t tau_min_us, std::int32_t tau_max_us) {
    tau_min_us_ = tau_min_us;
    tau_max_us_ = tau_max_us;
  }
  /// The loop's period h (µs): periods without a report are predicted over (0: off).
  constexpr void set_period_us(std::int32_t period_us) { period_us_ = period_us > 0 ? period_us : 0; }
  /// Sequence window W and re-acquisition count R (frame_checks.hpp).
  constexpr void set_sequence_window(std::uint32_t window, std::uint32_t reacquire) {
    gate_ = SequenceGate(window, reacquire);
  }

  /// The estimator (reset, covariance, …).
  constexpr Estimator& estimator() { return estimator_; }
  /// Period index of the last report used (valid after the first).
  constexpr SequenceNumber last_k() const { return gate_.last(); }
  /// The last command sent.
  constexpr const Vector<S, M>& last_command() const { return u_; }
  /// Counters.
  constexpr const SyncControllerStatistics& statistics() const { return stats_; }
  /// Worst status of the frames the last on_receive() handled (kOk when none).
  [[nodiscard]] constexpr FrameStatus receive_status() const { return receive_status_; }
  /// Result of the last command send (counted in statistics()).
  [[nodiscard]] constexpr SendResult last_send() const { return last_send_; }

 private:
  // round(dt / h) (µs; in 64 bits: no overflow at any dt).
  constexpr std::int32_t periods(std::int32_t dt) const {
    const std::int64_t h = period_us_;
    const std::int64_t d = dt;
    return static_cast<std::int32_t>(d >= 0 ? (d + h / 2) / h : -((-d + h / 2) / h));
  }

  // Periods between the last report's t_k and this one's: predicts the estimator over the
  // missing ones and moves the reference index by as many (kNonFinite: the estimator was reset).
  [[nodiscard]] Status fill_gap(const Report& r, McuInstant now) {
    const McuInstant t_k = r.t_s.plus(r.tau_us);
    const bool had = have_t_k_;
    const std::int32_t dt = t_k - last_t_k_;
    const std::int32_t dt_own = now - last_now_;
    last_t_k_ = t_k;
    last_now_ = now;
    have_t_k_ = true;
    if (period_us_ == 0 || !had) {
      ref_k_ = r.k;
      return Status::kOk;
    }
    // The stamps give n exactly; the controller's own clock (jittered by the delays) checks
    // them: a stamp more than one period off its count is wrong, the own count is taken.
    std::int32_t n = periods(dt);
    const std::int32_t n_own = periods(dt_own);
    if (n < 1 || n - n_own > 1 || n_own - n > 1) n = n_own < 1 ? 1 : n_own;
    ref_k_ += static_cast<SequenceNumber>(n);
    if (n - 1 > kMaxFilledPeriods) return Status::kOk;  // a long silence: the correction alone
    for (std::int32_t i = 1; i < n; ++i) {
      if (estimator_.skip(r.u_applied) == Status::kNonFinite) {
        ++stats_.estimator_resets;
        return Status::kNonFinite;
      }
      ++stats_.filled;
    }
    return Status::kOk;
  }

  void compute(const Report& r, McuInstant now) {
    if (fill_gap(r, now) == Status::kNonFinite) return;
    ++stats_.computations;
    const Status st = estimator_.update(r.tau_us, r.y, r.u_applied);
    if (!is_exact(st)) ++stats_.faults;
    if (st == Status::kNonFinite) {
      ++stats_.estimator_resets;
      return;
    }
    const Vector<S, M> u = reference_.input(ref_k_) - l_ * (estimator_.estimate() - reference_.state(ref_k_));
    if (!all_finite(u)) {
      ++stats_.withheld;
      return;
    }
    u_ = u;
    if (saturate(u_, u_min_, u_max_)) ++stats_.saturated;
    Command c;
    c.seq = r.k;
    c.stamp = now;
    c.payload.value = u_;
    last_send_ = send_message<Board>(actuator_, c, stats_);
  }

  std::uint8_t actuator_;
  Matrix<S, M, N> l_;
  Vector<S, M> u_min_;
  Vector<S, M> u_max_;
  Estimator estimator_;
  Reference reference_;
  Vector<S, M> u_{};
  std::int32_t period_us_ = 0;
  McuInstant last_t_k_{};
  McuInstant last_now_{};
  SequenceNumber ref_k_ = 0;
  bool have_t_k_ = false;
  std::int32_t tau_min_us_ = INT32_MIN;
  std::int32_t tau_max_us_ = INT32_MAX;
  SequenceGate gate_{};
  ExpectedSource source_{};
  ValueRange<S, P> y_range_{};
  ValueRange<S, M> echo_range_{};
  SyncControllerStatistics stats_{};
  FrameStatus receive_status_ = FrameStatus::kOk;
  SendResult last_send_ = SendResult::kSent;
};

}  // namespace oneshot::node
