/// @file board_loop.hpp
/// @brief One seed-000 run on the engine: the reference board plant, the control task
///        driven by the engine's timer and jitter events, the set-point schedule.
///
/// Events of period k (t_k = k h), in the kernel's order at equal times:
///   set-point change  (kEnvironment)  board advanced to the instant, new reference;
///   period start      (kActuation)    one-shot: timer interrupt (prepared duty applied);
///                                     then the period's job timing is drawn;
///   job               (kSample)       at t_k + release: ADC sample (measurement noise),
///                                     the control job; standard: its output is applied
///   job output        (kActuation)    at t_k + release + exec (standard model only);
///   end               (kEnd)          the board advanced to the end of the last period.
/// The board is advanced only at these events (each one draw of the process noise), so a
/// run's numbers do not depend on what is recorded: the state trace is bridged from its
/// own stream (board_plant.hpp). Streams: "process", "measurement", "jitter", "setpoint"
/// (make_schedule), "trace".
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>

#include "control_drivers.hpp"
#include "oneshot/engine/kernel.hpp"
#include "board_config.hpp"
#include "board_events.hpp"
#include "setpoint_volts.hpp"
#include "simulation.hpp"

namespace oneshot::sim {

/// Runs `sc` with `seed` on the board plant around `driver` (see the file comment).
template <std::size_t N, std::size_t M, std::size_t P, app::TaskModel kModel>
RunResult run_board_loop(const SimContext& ctx, const Scenario& sc, std::uint64_t seed, const RunOptions& opt,
                         BoardDriver<N, M>& driver) {
  using engine::Duration;
  using engine::EventClass;
  using engine::SimTime;
  const design::PlantDescription& plant = ctx.plant();
  const design::DesignResult& d = ctx.design();
  const JitterModel jitter = info(opt.approach).jitter ? sc.jitter : JitterModel{};
  engine::Kernel kernel(seed);
  BoardPlant<N, M, P> board(circuit_config<N, M, P>(plant, d, opt.board), kernel.stream("process"));
  RandomStream jitter_rng = kernel.stream("jitter");
  RandomStream measurement_rng = kernel.stream("measurement");
  const SetpointSchedule schedule = make_schedule(sc, plant, seed);
  const auto setpoint_at = [&](SimTime t) { return setpoint_volts_at<P>(d, schedule, t); };

  // Initial conditions: circuit at rest, the PWM at the code nearest 0 V in force from
  // power-on (whatever the register mode), the estimator agreeing.
  std::int32_t initial_codes[M] = {};
  for (std::size_t j = 0; j < M; ++j) {
    initial_codes[j] = static_cast<std::int32_t>(std::lround(-d.u_min[j] * d.steps_per_volt[j]));
    board.initialize_duty(j, initial_codes[j]);
    initial_codes[j] = board.duty(j);
  }
  board.set_setpoint(setpoint_at(SimTime{0}));
  driver.reset(initial_codes, opt.p0_scale);
  if (opt.trace_step_us > 0) board.record_trace(engine::from_us(opt.trace_step_us), kernel.stream("trace"));

  host::HostBoardState hb;
  hb.adc_codes.assign(P, 0);
  hb.setpoint_context = &schedule;
  hb.setpoint_at = [](const void* c, std::size_t, std::uint64_t at_us) {
    return static_cast<const SetpointSchedule*>(c)->code_at(static_cast<std::int64_t>(at_us) * 1000);
  };
  const host::ScopedHostBoard scope(hb);

  RunResult result;
  const Duration h = engine::from_us(plant.period_us);
  const BoardPeriods run_periods = board_periods(sc.duration_s, h);
  const std::int64_t periods = run_periods.count;
  const SimTime end = run_periods.end;
  const auto us_of = [](SimTime t) { return static_cast<std::uint64_t>(t.count() / 1000); };  // 64-bit: no wrap
  const auto apply_writes = [&]() {
    for (const host::PwmWrite& w : hb.pwm_writes) board.set_duty(w.channel, w.code);
    hb.pwm_writes.clear();
  };
  const double r_sigma = std::sqrt(plant.measurement_covariance(0, 0));
  JobTiming current{};  // timing of the period in progress (its job ends before the next period)

  const engine::HandlerId on_setpoint = kernel.add_handler("set-point change", [&](std::uint64_t) {
    board.advance_to(kernel.now());
    board.set_setpoint(setpoint_at(kernel.now()));
  });
  const engine::HandlerId on_output = kernel.add_handler("job output", [&](std::uint64_t) {
    board.advance_to(kernel.now());
    apply_writes();
  });
  const engine::HandlerId on_job = kernel.add_handler("control job", [&](std::uint64_t k) {
    const SimTime t_s = kernel.now();
    const SimTime t_k{static_cast<std::int64_t>(k) * h.count()};
    board.advance_to(t_s);
    for (std::size_t o = 0; o < P; ++o) hb.adc_codes[o] = board.adc_code(o, r_sigma * measurement_rng.normal());
    hb.now_us = us_of(t_s);
    hb.next_actuation_us = us_of(t_k + h);
    const JobReport<N> report = driver.job(hb);
    const JobTiming jt = current;
    if (opt.record_jobs) {
      JobRecord r;
      r.t_sample_s = engine::to_seconds(t_s);
      r.tau_us = report.tau_us;
      r.y_volts = code_volts(d, 0, hb.adc_codes[0]);
      for (std::size_t i = 0; i < N; ++i) {
        r.x_true.push_back(board.state()[i]);
        r.estimate.push_back(report.estimate[i]);
      }
      r.gain0 = report.gain0;
      const SimTime t_apply = kModel == app::TaskModel::kOneShot ? t_k + h : t_s;
      r.setpoint_code = schedule.code_at(t_apply.count());
      r.setpoint_volts = code_volts(d, 0, r.setpoint_code);
      r.y_code = hb.adc_codes[0];
      r.t_apply_s = engine::to_seconds(kModel == app::TaskModel::kOneShot ? t_apply : t_s + engine::from_us(jt.exec_us));
      r.u_volts = report.u_applied;
      result.job_records.push_back(std::move(r));
    }
    if (kModel == app::TaskModel::kStandard) kernel.schedule(t_s + engine::from_us(jt.exec_us), EventClass::kActuation, on_output, k);
  });
  auto on_period_id = std::make_shared<engine::HandlerId>(0);
  *on_period_id = kernel.add_handler("period start", [&, on_period_id](std::uint64_t k) {
    const SimTime t_k = kernel.now();
    if (kModel == app::TaskModel::kOneShot && k > 0) {
      board.advance_to(t_k);
      hb.now_us = us_of(t_k);
      driver.actuation(hb);
      apply_writes();
    }
    current = jitter.draw(jitter_rng, k);
    kernel.schedule(t_k + engine::from_us(current.release_us), EventClass::kSample, on_job, k);
    if (static_cast<std::int64_t>(k) + 1 < periods) kernel.schedule(t_k + h, EventClass::kActuation, *on_period_id, k + 1);
  });
  const engine::HandlerId on_end = kernel.add_handler("end", [&](std::uint64_t) { board.advance_to(kernel.now()); });

  run_board_events(kernel, schedule, end, periods, *on_period_id, on_setpoint, on_end);

  result.cost = board.cost();
  result.duration_s = engine::to_seconds(end);
  result.jobs = driver.statistics().jobs;
  result.overruns = driver.statistics().overruns;
  result.faults = driver.statistics().faults;
  result.saturated = driver.saturated();
  result.events = kernel.events_run();
  for (const auto& s : board.trace()) {
    TracePoint p;
    p.t_s = engine::to_seconds(s.t);
    for (std::size_t i = 0; i < N; ++i) p.x.push_back(s.x[i]);
    p.setpoint_volts = s.r[0];
    p.u_volts = s.u[0];
    result.trace.push_back(std::move(p));
  }
  return result;
}

}  // namespace oneshot::sim
