/// @file control_task.hpp
/// @brief The control task of the firmware: the same code on the MCU and in the host harness.
///
/// One-shot model: the actuation timer interrupt applies, at each actuation instant
/// t_k, the codes the job prepared; the job samples whenever it runs, computes
/// τ = t_k − t_sample from the timer's compare value, and prepares the next codes.
/// Standard model: the job samples and writes the PWM as soon as it has computed.
#pragma once

#include <cstddef>
#include <cstdint>

#include "oneshot/control_law.hpp"
#include "oneshot/controller.hpp"
#include "oneshot/hal/board_contract.hpp"
#include "oneshot/fixed_point.hpp"
#include "oneshot/status.hpp"
#include "oneshot/time_us.hpp"

namespace oneshot::app {

/// Which task model the job follows.
enum class TaskModel : std::uint8_t {
  kOneShot,   ///< Strictly periodic actuation from the timer interrupt.
  kStandard,  ///< Actuation when the job finishes.
};

/// Counters a host or a debugger can read.
struct TaskStatistics {
  std::uint32_t jobs = 0;            ///< Jobs run.
  std::uint32_t overruns = 0;        ///< Actuation instants with no prepared value.
  std::uint32_t faults = 0;          ///< Jobs whose maths returned a non-exact status.
  std::int32_t last_tau_us = 0;      ///< τ of the last job.
  Status last_status = Status::kOk;  ///< Status of the last job.
};

/// Control task over board `Board` running controller `Ctrl`.
template <typename Board, typename Ctrl, TaskModel kModel>
class ControlTask {
  static_assert(hal::kHasTime<Board>, "Board::Time must provide static hal::TimeSnapshot<Rep> snapshot()");
  static_assert(hal::kHasPwm<Board>, "Board::Pwm must provide static void write_duty(std::size_t, std::int32_t)");
  static_assert(hal::kHasAdc<Board>, "Board::Adc must provide static std::int32_t sample(std::size_t)");
  static_assert(hal::kHasSetpointAt<Board>,
                "Board::Setpoint must provide static std::int32_t setpoint_code(std::size_t, InstantUs<Rep>)");

 public:
  static constexpr std::size_t kM = Ctrl::kM;
  static constexpr std::size_t kP = Ctrl::kP;

  /// Task around `controller` (which must outlive it).
  explicit ControlTask(Ctrl& controller) : controller_(&controller) {}

  /// Forgets any prepared output and clears the counters.
  void reset() {
    ready_ = false;
    stats_ = TaskStatistics{};
  }

  /// Actuation timer interrupt (one-shot): applies the prepared codes.
  void on_actuation_interrupt() {
    if constexpr (kModel == TaskModel::kOneShot) {
      if (!ready_) {
        ++stats_.overruns;  // keep the previous duty: the job did not finish in time
        return;
      }
      for (std::size_t j = 0; j < kM; ++j) Board::Pwm::write_duty(j, prepared_[j]);
      ready_ = false;
    }
  }

  /// The control job: sample, τ, estimator, control law, actuation codes. Status: the
  /// worst of the estimator's, kOutOfRange when τ lies beyond ±kMaxTauUs (garbage timer
  /// values: τ bounded), and kOverflow when a fixed-point operation of the job saturated.
  [[nodiscard]] Status run_job() {
    const auto time = Board::Time::snapshot();  // clock and timer of the same instant
    const auto t_sample = time.now;
    // One-shot: the output is applied at the next actuation instant t_k; standard: now.
    const auto t_apply = kModel == TaskModel::kOneShot ? time.next_actuation : t_sample;
    typename Ctrl::OutputVec y;
    typename Ctrl::OutputVec r;
    for (std::size_t o = 0; o < kP; ++o) {
      y[o] = output_of_code(controller_->design().sensor, o, Board::Adc::sample(o));
      r[o] = output_of_code(controller_->design().sensor, o, Board::Setpoint::setpoint_code(o, t_apply));
    }
    // τ = t_k − t_sample, wrap-safe, range-checked where it enters the core.
    DurationUs tau_us = 0;
    Status status = checked_duration(t_sample, t_apply, -kMaxTauUs, kMaxTauUs, tau_us);
    if (status != Status::kOk) tau_us = (t_apply - t_sample) > 0 ? kMaxTauUs : -kMaxTauUs;
    std::int32_t codes[kM] = {};
    if constexpr (kIsFixed<typename Ctrl::CovScalar>) {
      // The sticky flag keeps its meaning for the caller; this job's saturations become its status.
      const bool saturated_before = saturation_flag();
      clear_saturation_flag();
      status = worst_of(status, controller_->job(tau_us, y, r, codes));
      if (saturation_flag()) status = worst_of(status, Status::kOverflow);
      if (saturated_before) raise_saturation_flag();
    } else {
      status = worst_of(status, controller_->job(tau_us, y, r, codes));
    }
    ++stats_.jobs;
    stats_.last_tau_us = tau_us;
    stats_.last_status = status;
    if (!is_exact(status)) ++stats_.faults;
    if constexpr (kModel == TaskModel::kOneShot) {
      for (std::size_t j = 0; j < kM; ++j) prepared_[j] = codes[j];
      ready_ = true;
    } else {
      for (std::size_t j = 0; j < kM; ++j) Board::Pwm::write_duty(j, codes[j]);
    }
    return status;
  }

  /// Counters.
  const TaskStatistics& statistics() const { return stats_; }
  /// The controller.
  const Ctrl& controller() const { return *controller_; }

 private:
  Ctrl* controller_;
  volatile std::int32_t prepared_[kM] = {};  // shared with the interrupt: volatile keeps the order
  volatile bool ready_ = false;
  TaskStatistics stats_{};
};

}  // namespace oneshot::app
