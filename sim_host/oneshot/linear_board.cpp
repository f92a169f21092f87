/// @file linear_board.cpp
/// @brief The linear board's run loop (see linear_board.hpp): board_loop.hpp's events and
///        streams with the real-valued plant, sensor and actuator.
#include "linear_board.hpp"

#include <algorithm>
#include <cmath>
#include <memory>
#include <stdexcept>
#include <type_traits>

#include "controller_parts.hpp"
#include "estimator_memory.hpp"
#include "linear_tracker.hpp"
#include "board_events.hpp"
#include "setpoint_volts.hpp"
#include "oneshot/control_law.hpp"
#include "oneshot/design/fixed_size.hpp"
#include "oneshot/engine/kernel.hpp"
#include "oneshot/generated/plant_tables.hpp"

namespace oneshot::sim {
namespace {

template <typename Structure, app::TaskModel kModel, typename Design, typename Est>
LinearRunResult run_linear(const SimContext& ctx, const Scenario& sc, std::uint64_t seed, const RunOptions& opt,
                           const LinearOptions& lin, const Design& design, Est est) {
  using engine::Duration;
  using engine::EventClass;
  using engine::SimTime;
  using Fmt = typename Design::Format;
  constexpr std::size_t N = Design::kStates;
  constexpr std::size_t M = Design::kInputs;
  constexpr std::size_t P = Design::kOutputs;
  static_assert(std::is_same_v<typename Fmt::State, double> && std::is_same_v<typename Fmt::Input, double>,
                "the linear board runs the core in double");
  const design::PlantDescription& plant = ctx.plant();
  const design::DesignResult& d = ctx.design();
  const JitterModel jitter = info(opt.approach).jitter ? sc.jitter : JitterModel{};
  engine::Kernel kernel(seed);
  engine::RandomStream jitter_rng = kernel.stream("jitter");
  engine::RandomStream measurement_rng = kernel.stream("measurement");
  const SetpointSchedule schedule = make_schedule(sc, plant, seed);
  const bool process_noise = lin.noise && opt.board.process_noise;
  const engine::JumpLinearPlant<N, M> jp{design::to_fixed<double, N, N>(plant.a), design::to_fixed<double, N, M>(plant.b),
                                         design::to_fixed<double, N, N>(d.qc), design::to_fixed<double, N, N>(plant.q1c),
                                         design::to_fixed<double, M, M>(plant.q2c)};
  engine::JumpLinearPlant<N, M> sim_plant = jp;
  if (!process_noise || lin.analytic) sim_plant.qc = Matrix<double, N, N>{};
  LinearPlant<N, M> board(sim_plant, process_noise && !lin.analytic, kernel.stream("process"));
  const auto c = design::to_fixed<double, P, N>(plant.c);
  const auto nx = design::to_fixed<double, N, P>(d.nx);
  const auto nu = design::to_fixed<double, M, P>(d.nu);
  // The measurement noise is drawn and tracked as one scalar per job, R = R(0, 0): a plant with
  // several outputs would need R's Cholesky factor (draws) and its off-diagonal terms (tracker).
  static_assert(P == 1, "the linear board supports one output: its measurement noise is the scalar R(0, 0)");
  const double r_sigma = std::sqrt(plant.measurement_covariance(0, 0));
  const bool measurement_noise = lin.noise && !lin.analytic;
  const auto set_reference = [&](SimTime t, auto& target) {
    const Vector<double, P> r = setpoint_volts_at<P>(d, schedule, t);
    target.set_reference(nx * r, nu * r);
  };

  // Power-on: the input the board's initial duty averages to (the code nearest 0 V), held and
  // in the estimator's memory; x̂ = 0.
  Vector<double, M> u0;
  Vector<double, M> u_min;
  Vector<double, M> u_max;
  for (std::size_t j = 0; j < M; ++j) {
    const std::int32_t steps = plant.board.pwm_duty_steps;
    const auto code = std::clamp(static_cast<std::int32_t>(std::lround(-d.u_min[j] * d.steps_per_volt[j])), 0, steps);
    u_min[j] = plant.board.pwm_low_volts[j];
    u_max[j] = plant.board.pwm_high_volts[j];
    u0[j] = u_min[j] + (u_max[j] - u_min[j]) * code / steps;
  }
  auto p0 = design.p0;
  for (std::size_t k = 0; k < p0.kSize; ++k) p0[k] *= opt.p0_scale;
  est.reset(typename Est::StateVec{}, p0, u0);
  board.apply(u0);
  set_reference(SimTime{0}, board);

  std::unique_ptr<LinearTracker<N, M, P>> tracker;
  if (lin.analytic) {
    engine::JumpLinearPlant<N, M> tp = jp;
    Matrix<double, P, P> r{};
    if (lin.noise) {
      for (std::size_t o = 0; o < P; ++o) r(o, o) = r_sigma * r_sigma;
    } else {
      tp.qc = Matrix<double, N, N>{};
    }
    if (!opt.board.process_noise) tp.qc = Matrix<double, N, N>{};
    tracker = std::make_unique<LinearTracker<N, M, P>>(tp, c, r, u0, u_min, u_max);
    set_reference(SimTime{0}, *tracker);
  }

  LinearRunResult result;
  const Duration h = engine::from_us(plant.period_us);
  const BoardPeriods run_periods = board_periods(sc.duration_s, h);
  const std::int64_t periods = run_periods.count;
  const SimTime end = run_periods.end;
  Vector<double, M> prepared = u0;
  JobTiming current{};
  const auto advance = [&](SimTime t) {
    board.advance_to(t);
    if (tracker) tracker->flow_to(t);
  };
  const auto actuate = [&]() {
    board.apply(prepared);
    if (tracker) tracker->apply(prepared);
  };

  const engine::HandlerId on_setpoint = kernel.add_handler("set-point change", [&](std::uint64_t) {
    advance(kernel.now());
    set_reference(kernel.now(), board);
    if (tracker) set_reference(kernel.now(), *tracker);
  });
  const engine::HandlerId on_output = kernel.add_handler("job output", [&](std::uint64_t) {
    advance(kernel.now());
    actuate();
  });
  const engine::HandlerId on_job = kernel.add_handler("control job", [&](std::uint64_t k) {
    const SimTime t_s = kernel.now();
    const SimTime t_k{static_cast<std::int64_t>(k) * h.count()};
    advance(t_s);
    Vector<double, P> y = c * board.state();
    if (measurement_noise)
      for (std::size_t o = 0; o < P; ++o) y[o] += r_sigma * measurement_rng.normal();
    const SimTime t_apply = kModel == app::TaskModel::kOneShot ? t_k + h : t_s;
    const auto tau_us = static_cast<std::int32_t>((t_apply - t_s).count() / 1000);
    typename Est::OutputVec r;
    for (std::size_t o = 0; o < P; ++o) r[o] = output_of_code(design.sensor, o, schedule.code_at(t_apply.count()));
    const bool first_job = result.jobs == 0;
    const Est before = est;
    const Status status = est.update(tau_us, y);
    const Vector<double, M> u = control_law<Fmt, Structure>(design, est.prediction(), r);
    est.set_applied_input(u);
    ++result.jobs;
    if (lin.record_jobs) result.job_records.push_back(LinearJobRecord{engine::to_seconds(t_s), tau_us});
    if (!is_exact(status)) {
      ++result.faults;
      if (tracker) tracker->refuse(kLinearRefusalInexact);
    }
    for (std::size_t j = 0; j < M; ++j)
      if (!(u[j] >= u_min[j] && u[j] <= u_max[j])) ++result.out_of_range;
    if (tracker) {
      const auto eval = [&](const Vector<double, LinearTracker<N, M, P>::kW>& w) {
        Est e = before;
        Vector<double, P> yw;
        Vector<double, N> xw;
        Vector<double, M> ul;
        Vector<double, M> up;
        for (std::size_t o = 0; o < P; ++o) yw[o] = w[o];
        for (std::size_t i = 0; i < N; ++i) xw[i] = w[P + i];
        for (std::size_t j = 0; j < M; ++j) {
          ul[j] = w[P + N + j];
          up[j] = w[P + N + M + j];
        }
        set_memory(e, design, xw, ul, up, first_job);
        (void)e.update(tau_us, yw);
        const Vector<double, M> uw = control_law<Fmt, Structure>(design, e.prediction(), r);
        e.set_applied_input(uw);
        const Vector<double, N> xa = memory_estimate(e);
        Vector<double, N + M> out;
        for (std::size_t i = 0; i < N; ++i) out[i] = xa[i];
        for (std::size_t j = 0; j < M; ++j) out[N + j] = uw[j];
        return out;
      };
      tracker->job(eval, memory_estimate(est), u);
    }
    prepared = u;
    if (kModel == app::TaskModel::kStandard) {
      kernel.schedule(t_s + engine::from_us(current.exec_us), EventClass::kActuation, on_output, k);
    }
  });
  auto on_period_id = std::make_shared<engine::HandlerId>(0);
  *on_period_id = kernel.add_handler("period start", [&, on_period_id](std::uint64_t k) {
    const SimTime t_k = kernel.now();
    if (kModel == app::TaskModel::kOneShot && k > 0) {
      advance(t_k);
      actuate();
    }
    current = jitter.draw(jitter_rng, k);
    kernel.schedule(t_k + engine::from_us(current.release_us), EventClass::kSample, on_job, k);
    if (static_cast<std::int64_t>(k) + 1 < periods) kernel.schedule(t_k + h, EventClass::kActuation, *on_period_id, k + 1);
  });
  const engine::HandlerId on_end = kernel.add_handler("end", [&](std::uint64_t) { advance(kernel.now()); });
  run_board_events(kernel, schedule, end, periods, *on_period_id, on_setpoint, on_end);

  result.cost = board.cost();
  if (tracker) {
    result.analytic = tracker->cost();
    result.refusal = tracker->refusal();
    result.mismatch = tracker->mismatch();
  }
  return result;
}

}  // namespace

LinearRunResult run_linear_board(const SimContext& ctx, const Scenario& sc, std::uint64_t seed, const RunOptions& opt,
                                 const LinearOptions& lin) {
  validate_scenario(sc, ctx.plant());
  if (!ctx.generated()) {
    throw std::invalid_argument("the linear board runs the compiled-in plant: run without --plant (or configure the "
                                "build with -DONESHOT_PLANT=FILE)");
  }
  if (!approach_available(ctx, opt.approach)) {
    throw std::invalid_argument(std::string("approach ") + info(opt.approach).letter +
                                " is unavailable for this plant: " + ctx.design().deadbeat_unavailable_reason);
  }
  using K = generated::PlantConstants<double>;
  return with_estimator<generated::PlantStructure>(
      opt, K::kDesign, K::kTable, K::kModel, [&](auto structure, auto model, const auto& design, const auto& estimator) {
        return run_linear<typename decltype(structure)::type, decltype(model)::value>(ctx, sc, seed, opt, lin, design,
                                                                                     estimator);
      });
}

}  // namespace oneshot::sim
