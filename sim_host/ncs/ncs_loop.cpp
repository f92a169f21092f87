/// @file ncs_loop.cpp
/// @brief One run of study `ncs` on the engine (see ncs_loop.hpp).
#include "ncs_loop.hpp"

#include <functional>
#include <memory>
#include <optional>
#include <stdexcept>
#include <type_traits>
#include <vector>

#include "ncs_counters.hpp"
#include "ncs_harness.hpp"
#include "oneshot/node/actuator_node.hpp"
#include "oneshot/node/controller_node.hpp"
#include "oneshot/node/periodic_trigger.hpp"
#include "oneshot/node/sampling_sync_laws.hpp"
#include "oneshot/node/sensor_node.hpp"
#include "oneshot/node/sync_estimators.hpp"

namespace oneshot::ncs::loop {
namespace {

/// The Kalman law of the sampling loops SK, IK on the plant of shape S (its filter has a covariance: the NEES).
template <typename S>
using KalmanLawOf = node::PeriodicKalmanLaw<Fmt, typename BasicHarness<S>::Structure, typename BasicHarness<S>::Ref>;
/// True for a sampling loop's law with a Kalman filter.
template <typename Law>
struct IsKalmanLaw : std::false_type {};
/// The periodic Kalman law.
template <typename F, typename St, typename R>
struct IsKalmanLaw<node::PeriodicKalmanLaw<F, St, R>> : std::true_type {};
/// True for a sampling loop's law with a Kalman filter.
template <typename Law>
constexpr bool kIsKalmanLaw = IsKalmanLaw<Law>::value;
/// The sampling-synchronized baseline with law `law` on the plant of shape S; `saturated(law)`
/// reads its count. The sensor sends K values: y (K = p: BasicHarness::sample()) or, with
/// `state_sensor` (K = n), the state x (BasicHarness::sample_state(): I, and S on C = I, when
/// y is not x: C ≠ I or a padded shape).
template <typename S, std::size_t K, typename Law, typename Saturated>
RunResult run_sampling(BasicHarness<S>& hs, Law law, Saturated saturated, bool state_sensor = false) {
  using Trigger = node::PeriodicTrigger<double, K>;
  using Sensor = node::SensorNode<Board, Trigger, double, K>;
  using Ctrl = node::ControllerNode<Board, Law, double, K, S::m>;
  using Act = node::ActuatorNode<Board, double, S::m>;
  using InputVec = typename BasicHarness<S>::InputVec;
  using OutputVec = Vector<double, K>;
  const auto take_sample = [&hs, state_sensor]() -> OutputVec {
    if constexpr (K == S::n) {
      if (state_sensor) return hs.sample_state();
    }
    if constexpr (K == S::p) {
      return hs.sample();
    } else {
      if (!state_sensor) throw std::logic_error("ncs: a sensor of n values sends the state");
      return hs.sample_state();
    }
  };
  const std::uint8_t sensor_at = hs.sensor_at_, controller_at = hs.controller_at_, actuator_at = hs.actuator_at_;
  std::optional<Sensor> sensor(std::in_place, controller_at, Trigger(1));
  std::optional<Ctrl> ctrl(std::in_place, actuator_at, node::ControllerMode::kOnArrival, law);
  std::optional<Act> act(std::in_place, node::ActuatorMode::kOnArrival, InputVec{});
  const auto check_ctrl = [&]() { ctrl->expect_source(sensor_at); };  // samples: finite (the plant is not clamped)
  const auto check_act = [&]() {  // live::check_commands() for any shape
    act->expect_source(controller_at);
    act->set_command_range(hs.u_min_, hs.u_max_);
  };
  check_ctrl();
  check_act();
  std::uint64_t sensor_n0 = 0;  // sample index of the sensor's power-on (its sequence = n − n0)
  bool sensor_restarted = false;
  engine::Network& net = hs.net_;
  engine::Kernel& k = hs.kernel_;
  std::uint32_t samples = 0;  // the sequence number of the next sample (no restart in analytic runs)
  // The NEES (the Kalman law of SK, IK): x̂_{k|k}, P_{k|k} of each computation against the true
  // state at its sample's instant (kh; the sampling job's sample point on a CPU), by sequence number.
  std::vector<Vector<double, S::n>> truth;
  std::vector<bool> truth_set;
  const auto note_truth = [&](node::SequenceNumber seq) {
    if (!kIsKalmanLaw<Law> || !hs.opt_faults_empty_) return;
    if (truth.size() <= seq) {
      truth.resize(seq + std::size_t{1});
      truth_set.resize(seq + std::size_t{1}, false);
    }
    truth[seq] = hs.plant_.state();
    truth_set[seq] = true;
  };
  const HandlerId compute_h = k.add_handler("compute", [&](std::uint64_t) {
    const Law before = ctrl->law();
    const std::uint32_t runs = ctrl->statistics().computations;
    net.run_node(controller_at, [&]() { ctrl->on_receive(net.node_clock(controller_at)); });
    hs.tracker([&](auto& t) { t.compute_law(before, samples - 1); });
    if constexpr (kIsKalmanLaw<Law>) {
      const node::SequenceNumber seq = ctrl->latest().seq;
      if (ctrl->statistics().computations != runs && seq < truth.size() && truth_set[seq]) {
        hs.add_nees(truth[seq], ctrl->law().filter().prediction(), ctrl->law().filter().covariance());
      }
    }
  });
  // Each node's clock reads t − φ of its own offset (Scenario::sensor_clock_us; the sensor's is
  // the loop's phase): only the sensor's stamps read one, which the laws do not use.
  net.add_node(sensor_at, "sensor", hs.clock_offset_of(hs.sc_.sensor_clock_us), nullptr);
  net.add_node(controller_at, "controller", hs.clock_offset_of(hs.sc_.controller_clock_us),
               [&]() { hs.start_computation(compute_h); });
  net.add_node(actuator_at, "actuator", hs.clock_offset_of(hs.sc_.actuator_clock_us), [&]() {
    act->on_receive();
    InputVec u;
    if (act->take_output(u)) hs.apply(u);
  });
  hs.route_leg(sensor_at, controller_at, "sc");
  hs.route_leg(controller_at, actuator_at, "ca");
  net.arm_faults({{"sensor",
                   [&]() {
                     sensor.emplace(controller_at, Trigger(1));
                     sensor_restarted = true;
                   }},
                  {"controller",
                   [&]() {
                     ctrl.emplace(actuator_at, node::ControllerMode::kOnArrival, law);
                     check_ctrl();
                     hs.lose_inbox(controller_at);
                   }},
                  {"actuator", [&]() {
                     act.emplace(node::ActuatorMode::kOnArrival, InputVec{});
                     check_act();
                     hs.lose_inbox(actuator_at);
                   }}});
  // The sensor on a CPU (ncs_cpu.hpp): the timer releases its job n, which samples at its
  // sample point and sends at its finish (per job: its sequence number and sample).
  struct SensorJob {
    node::SequenceNumber seq = 0;
    OutputVec y{};
    bool sampled = false;
  };
  std::vector<SensorJob> jobs;
  if (hs.sensor_cpu_) {
    hs.sensor_cpu_->on_point([&](std::size_t e, std::uint64_t n, engine::cpu::CpuEventKind kind) {
      if (e != hs.sensor_task_ || kind != engine::cpu::CpuEventKind::kSample || n >= jobs.size()) return;
      jobs[n].y = take_sample();
      note_truth(jobs[n].seq);
      jobs[n].sampled = true;
      ++samples;
    });
    hs.sensor_cpu_->on_job([&](const engine::cpu::CpuJob& j) {
      if (j.entity != hs.sensor_task_ || j.aborted || j.index >= jobs.size() || !jobs[j.index].sampled) return;
      const SensorJob& s = jobs[j.index];
      net.run_node(sensor_at, [&]() { sensor->on_sample(s.seq, net.node_clock(sensor_at), s.y); });
    });
  }
  auto timer_h = std::make_shared<HandlerId>(0);
  *timer_h = k.add_handler("sample", [&, timer_h](std::uint64_t n) {
    if (sensor_restarted) {
      sensor_restarted = false;
      sensor_n0 = n;
    }
    if (hs.sensor_cpu_) {
      jobs.push_back(SensorJob{static_cast<node::SequenceNumber>(n - sensor_n0), OutputVec{}, false});
      hs.sensor_cpu_->release(hs.sensor_task_);
      const SimTime t_next = k.now() + hs.h_;
      if (t_next < hs.end_) k.schedule(t_next, EventClass::kSample, *timer_h, n + 1);
      return;
    }
    const OutputVec y = take_sample();
    ++samples;
    const auto seq = static_cast<node::SequenceNumber>(n - sensor_n0);
    note_truth(seq);
    net.run_node(sensor_at, [&]() { sensor->on_sample(seq, net.node_clock(sensor_at), y); });
    const SimTime t_next = k.now() + hs.h_;
    if (t_next < hs.end_) k.schedule(t_next, EventClass::kSample, *timer_h, n + 1);
  });
  k.schedule(SimTime{hs.offset_}, EventClass::kSample, *timer_h, 0);  // at kh + φ (φ = 0 but in a run of several loops)
  RunResult r = hs.finish();
  r.saturated = saturated(ctrl->law());
  if constexpr (kIsKalmanLaw<Law>) r.faults = ctrl->law().faults();  // corrections not exact (skipped)
  r.counters = concat(sampling_controller_counters(*ctrl), actuator_counters(*act));
  return r;
}

}  // namespace
}  // namespace oneshot::ncs::loop

namespace oneshot::ncs {

using namespace loop;  // NOLINT: the loops' aliases and Harness (ncs_harness.hpp)

RunResult run(const Context& ctx, Approach a, const Scenario& sc, std::uint64_t seed, const RunOptions& options) {
  RunResult r = run_approach(ctx, a, sc, seed, options);
  if (options.analytic) refuse_nonlinear_runs(r);
  return r;
}

namespace {

/// Approach `a`'s loop on `hs`: every approach on the board's plant, the sampling loops I, S,
/// SK, IK on another (std::invalid_argument naming the approach otherwise): I feeds the true
/// state back (for n ≤ 6: x fits a frame), S the measured one (C = I), SK and IK filter y.
template <typename S>
RunResult run_on(BasicHarness<S>& hs, Approach a) {
  const Context& ctx = hs.ctx_;
  const Scenario& sc = hs.sc_;
  const Vector<double, S::n> x0 = hs.ref_.state(0);
  using Ref = typename BasicHarness<S>::Ref;
  using Feedback = node::StateFeedbackLaw<double, S::n, S::m, Ref>;
  using Kalman = KalmanLawOf<S>;
  const std::string plant_shape = "a plant of n = " + std::to_string(ctx.states()) + ", m = " + std::to_string(ctx.inputs()) +
                                  ", p = " + std::to_string(ctx.outputs());
  switch (a) {
    case Approach::kI:
    case Approach::kS:
      if (a == Approach::kS && !ctx.identity_output()) {
        throw std::invalid_argument("ncs: approach S feeds y back as x: it needs C = I (" + plant_shape + ")");
      }
      if constexpr (S::n <= kMaxStateFeedbackStates) {
        // y is x (C = I on a shape with p = n: the board's runs as before, to the bit), else x itself
        const bool y_is_x = S::p == S::n && ctx.identity_output();
        return run_sampling<S, S::n>(hs, Feedback{hs.design_.l, hs.u_min_, hs.u_max_, hs.ref_},
                                     [](const Feedback& f) { return f.saturated; }, !y_is_x);
      } else {
        throw std::invalid_argument(std::string("ncs: approach ") + name(a) + " sends the state in one frame: n <= 6 only (" +
                                    plant_shape + ")");
      }
    case Approach::kSK:
    case Approach::kIK: {
      Kalman law(hs.design_, NoiseModel::kConstant, hs.u_min_, hs.u_max_, hs.ref_);
      law.filter().reset(x0, hs.design_.p0, typename BasicHarness<S>::InputVec{});
      return run_sampling<S, S::p>(hs, law, [](Kalman& f) { return f.saturated(); });
    }
    default:
      break;
  }
  if (!ctx.board()) {
    throw std::invalid_argument(std::string("ncs: approach ") + name(a) + " runs the board's plant (n = 2, m = 1, p = 2, C = I) only; " +
                                plant_shape + " runs I, S, SK, IK");
  }
  if constexpr (BasicHarness<S>::kBoard) {
    using Compensated = node::DelayCompensatedLaw<double, kN, kM, Ref>;
    switch (a) {
      case Approach::kA:
      case Approach::kAK:
      case Approach::kAKx:
      case Approach::kAKl:
        return run_synchronized(hs, a);
      case Approach::kSPlus: {
        const SplitGain g = delay_compensated_split(ctx, ctx.mean_tau_io_us(sc));
        Compensated law{g.lx, g.lu, hs.u_min_, hs.u_max_, hs.ref_};
        return run_sampling<S, S::p>(hs, law, [](const Compensated& f) { return f.saturated; });
      }
      case Approach::kOS:
      case Approach::kOSp:
      case Approach::kOSK:
        return run_one_shot(hs, a);
      default:
        throw std::logic_error("ncs: unknown approach");
    }
  } else {
    static_cast<void>(sc);
    throw std::logic_error("ncs: the board's plant runs on the board's shape");
  }
}

/// fn(S{}) with the shape S of ONESHOT_NCS_SHAPES the plant of `ctx` runs on (ncs_shape_of(), or
/// `force` when set: it must hold the plant); std::invalid_argument naming plant.continuous.A
/// when none does (Context refuses such plants first).
template <typename Fn>
auto on_shape(const Context& ctx, Fn&& fn, NcsShapeOf force = {}) -> decltype(fn(BoardShape{})) {
  const std::size_t n = ctx.states();
  const std::size_t m = ctx.inputs();
  const std::size_t p = ctx.outputs();
  const NcsShapeOf on = force.n != 0 ? force : ncs_shape_of(n, m, p);
  if (on.n < n || on.m < m || on.p < p) {
    throw std::invalid_argument("ncs: the shape (" + std::to_string(on.n) + ", " + std::to_string(on.m) + ", " + std::to_string(on.p) +
                                ") does not hold a plant of n = " + std::to_string(n) + ", m = " + std::to_string(m) + ", p = " +
                                std::to_string(p));
  }
#define ONESHOT_NCS_ON_SHAPE(n_, m_, p_) \
  if (on.n == (n_) && on.m == (m_) && on.p == (p_)) return fn(Shape<n_, m_, p_>{});
  ONESHOT_NCS_SHAPES(ONESHOT_NCS_ON_SHAPE)
#undef ONESHOT_NCS_ON_SHAPE
  throw std::invalid_argument("plant.continuous.A: the ncs loops run no plant of n = " + std::to_string(n) + ", m = " + std::to_string(m) +
                              ", p = " + std::to_string(p));
}

}  // namespace

std::int64_t loop_phase_us(Approach a, const Scenario& s) {
  if (one_shot(a)) return 0;
  return actuation_synchronized(a) ? s.actuator_clock_us : s.sensor_clock_us;
}

Scenario at_phase_zero(Scenario s, Approach a) {
  const std::int64_t phi = loop_phase_us(a, s);
  if (one_shot(a) || phi == 0) return s;
  s.sensor_clock_us -= phi;  // the timer node's to 0, the others by as much
  s.controller_clock_us -= phi;
  s.actuator_clock_us -= phi;
  return s;
}

RunResult run_approach(const Context& ctx, Approach a, const Scenario& sc, std::uint64_t seed, const RunOptions& options) {
  return on_shape(ctx, [&](auto shape) {
    BasicHarness<decltype(shape)> hs(ctx, a, sc, seed, options);
    return run_on(hs, a);
  }, options.force_shape);
}

std::vector<RunResult> run_loops(const std::vector<LoopOnBus>& loops, Approach a, std::uint64_t seed, ShapeCachePools* caches) {
  if (loops.empty()) throw std::invalid_argument("ncs: run_loops needs a loop");
  if (a != Approach::kI && a != Approach::kS && a != Approach::kSK && a != Approach::kIK) {
    throw std::invalid_argument(std::string("ncs: several loops in one run take I, S, SK, IK, not ") + name(a));
  }
  World world(seed);
  for (const LoopOnBus& l : loops) {  // the run's end before any loop builds a bus: the background runs to it
    const SimTime end = engine::from_us(l.clock_offset_us) + engine::from_seconds(l.scenario->duration_s, "ncs scenario duration");
    if (end > world.end) world.end = end;
  }
  std::vector<RunResult> out(loops.size());
  RunOptions options;  // the defaults but the sweep's shared caches
  options.caches = caches;
  // Loop i's nodes and timers are set up, then loop i + 1's inside its finish(); the last runs
  // the kernel, and each collects its results as the calls return.
  std::function<void(std::size_t)> run_from = [&](std::size_t i) {
    const LoopOnBus& l = loops[i];
    out[i] = on_shape(*l.ctx, [&](auto shape) {  // each loop on its own plant's shape
      BasicHarness<decltype(shape)> hs(*l.ctx, a, *l.scenario, seed, options, &world, &l);
      if (i + 1 < loops.size()) hs.inner_ = [&run_from, i]() { run_from(i + 1); };
      return run_on(hs, a);
    });
  };
  run_from(0);
  return out;
}

}  // namespace oneshot::ncs
