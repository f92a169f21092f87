/// @file c_job_driver.hpp
/// @brief The generated C99 job (oneshot_job.c compiled into the host build) as the board
///        loop's control task: the very adapter the firmware runs (firmware/app/mcu/
///        c_job_loop.hpp) over the host port, so that host runs and MCU runs execute the same
///        C code on the same inputs (approach B's job: half Kalman, one-shot, exact Q_d).
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <stdexcept>

#include "c_job_loop.hpp"
#include "control_drivers.hpp"
#include "oneshot/fixed_point.hpp"
#include "oneshot/host/host_board.hpp"

namespace oneshot::sim {

/// A C job on the host: J names its state, init and run (as CJobLoop wants) and the binary
/// points of its estimate, gain and input (kStateFrac, kGainFrac, kInputFrac).
template <typename J, std::size_t N>
class CJobDriver final : public BoardDriver<N, 1> {
 public:
  void reset(const std::int32_t (&codes)[1], double p0_scale) override {
    if (p0_scale != 1.0) throw std::invalid_argument("the C job starts from the design's initial covariance (p0 scale 1)");
    clear_saturation_flag();
    loop_.configure(codes);
  }
  void actuation(host::HostBoardState&) override { loop_.task.on_actuation_interrupt(); }
  JobReport<N> job(host::HostBoardState&) override {
    (void)loop_.task.run_job();  // the task keeps the status in its statistics (statistics())
    JobReport<N> r;
    r.tau_us = loop_.task.statistics().last_tau_us;
    for (std::size_t i = 0; i < N; ++i) r.estimate[i] = std::ldexp(static_cast<double>(loop_.state.x[i]), -J::kStateFrac);
    r.gain0 = std::ldexp(static_cast<double>(loop_.state.k[0]), -J::kGainFrac);
    r.u_applied = std::ldexp(static_cast<double>(loop_.state.u[0]), -J::kInputFrac);
    return r;
  }
  const app::TaskStatistics& statistics() const override { return loop_.task.statistics(); }
  bool saturated() const override { return saturation_flag(); }

 private:
  mcu::CJobLoop<J, host::HostBoard, N> loop_;
};

}  // namespace oneshot::sim
