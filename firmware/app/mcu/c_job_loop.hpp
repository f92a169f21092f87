/// @file c_job_loop.hpp
/// @brief The generated C99 job (oneshot_job.h) behind the firmware's control-task interface,
///        for the PIL image's approaches 5 and 6 (main.cpp): τ from the timer, ADC and
///        set-point codes in, the PWM code written at the next actuation instant.
#pragma once

#include <cstddef>
#include <cstdint>
#include <type_traits>

#include "oneshot/app/control_task.hpp"
#include "oneshot/app/pil_protocol.hpp"
#include "oneshot/fixed_point.hpp"
#include "oneshot/status.hpp"
#include "oneshot/time_us.hpp"

namespace oneshot::mcu {


/// A generated C job behind the control task's interface: J names its state type, init and
/// run (and kFixed: it has the sticky saturation flag), Board the board port, kN the states.
template <typename J, typename Board, std::size_t kN>
struct CJobLoop {
  typename J::State state{};
  struct Task {
    CJobLoop* self;
    volatile std::int32_t prepared = 0;  // shared with the interrupt
    volatile bool ready = false;
    app::TaskStatistics stats{};
    [[nodiscard]] Status run_job() {
      const auto time = Board::Time::snapshot();
      const auto t_apply = time.next_actuation;
      DurationUs tau_us = 0;
      Status status = checked_duration(time.now, t_apply, -kMaxTauUs, kMaxTauUs, tau_us);
      if (status != Status::kOk) tau_us = (t_apply - time.now) > 0 ? kMaxTauUs : -kMaxTauUs;
      const auto adc = static_cast<std::uint16_t>(Board::Adc::sample(0));
      const auto sp = static_cast<std::uint16_t>(Board::Setpoint::setpoint_code(0, t_apply));
      std::uint8_t saturated_before = 0U;
      if constexpr (J::kFixed) {
        saturated_before = self->state.saturated;
        self->state.saturated = 0U;
      }
      prepared = J::run(&self->state, tau_us, adc, sp);
      ready = true;
      ++stats.jobs;
      stats.last_tau_us = tau_us;
      status = worst_of(status, static_cast<Status>(self->state.status));
      if constexpr (J::kFixed) {
        // As ControlTask: this job's saturation is its status, the sticky flags keep their meaning.
        if (self->state.saturated != 0U) {
          status = worst_of(status, Status::kOverflow);
          detail::g_saturated = true;  // the reply's flag, as for the C++ job
        }
        if (saturated_before != 0U) self->state.saturated = 1U;
      }
      stats.last_status = status;
      if (!is_exact(stats.last_status)) ++stats.faults;
      return stats.last_status;
    }
    void on_actuation_interrupt() {
      if (!ready) {
        ++stats.overruns;
        return;
      }
      Board::Pwm::write_duty(0, prepared);
      ready = false;
    }
    const app::TaskStatistics& statistics() const { return stats; }
  } task{this};

  void configure(const std::int32_t (&codes)[1]) {
    J::init(&state, static_cast<std::uint16_t>(codes[0]));
    task.ready = false;
    task.stats = app::TaskStatistics{};
  }
  template <typename T>
  static std::uint32_t raw(T v) {
    if constexpr (std::is_floating_point_v<T>) {
      static_assert(sizeof(T) == 4, "the firmware reports single precision");
      std::uint32_t u = 0;
      __builtin_memcpy(&u, &v, 4);
      return u;
    } else {
      return static_cast<std::uint32_t>(static_cast<std::int32_t>(v));
    }
  }
  void results(app::pil::Writer& w) const {
    w.u(raw(state.u[0]), 4);
    for (std::size_t i = 0; i < kN; ++i) w.u(raw(state.x[i]), 4);
    w.u(raw(state.k[0]), 4);
  }
};

}  // namespace oneshot::mcu
