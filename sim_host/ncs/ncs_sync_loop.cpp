/// @file ncs_sync_loop.cpp
/// @brief The actuation-synchronized loops A, AK, AKx, AKl of study ncs on the board's plant
///        (brief §1): sensor, controller and actuator nodes synchronized at the actuation
///        instants, the estimator's NEES (see ncs_harness.hpp).
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <type_traits>

#include "ncs_counters.hpp"
#include "ncs_harness.hpp"
#include "oneshot/node/sync_actuator_node.hpp"
#include "oneshot/node/sync_controller_node.hpp"
#include "oneshot/node/sync_estimators.hpp"
#include "oneshot/node/sync_sensor_node.hpp"

namespace oneshot::ncs::loop {
namespace {

/// True for an actuation-synchronized estimator with a covariance (AK, AKx, AKl; not A's predictor).
template <typename Estimator>
constexpr bool kHasCovariance = !std::is_same_v<Estimator, node::SampledStatePredictor<Fmt, Structure, Disc>>;

/// The actuation-synchronized loop with estimator `est` (brief §1).
template <typename Estimator>
RunResult run_synchronized(Harness& hs, Estimator est, std::int32_t late_us) {
  using Act = node::SyncActuatorNode<Board, double, kM>;
  using Sensor = node::SyncSensorNode<Board, double, kP, kM>;
  using Ctrl = node::SyncControllerNode<Board, Estimator, Ref, double, kN, kP, kM>;
  Matrix<double, kM, kN> l = hs.design_.l;
  // Optional: a restart rebuilds the node as at power-on.
  std::optional<Act> act(std::in_place, kSensor, InputVec{});
  std::optional<Sensor> sensor(std::in_place, kController, late_us);
  std::optional<Ctrl> ctrl(std::in_place, kActuator, l, hs.u_min_, hs.u_max_, est, hs.ref_);
  // Frame checks as in the live run (ncs_live_nodes.hpp), again after every restart.
  const auto check_sensor = [&]() { live::check_requests(hs.ctx_, *sensor); };
  const auto check_ctrl = [&]() { live::check_reports(hs.ctx_, *ctrl); };
  const auto check_act = [&]() { live::check_commands(hs.ctx_, *act); };
  check_sensor();
  check_ctrl();
  check_act();
  std::uint64_t act_n0 = 0;  // timer index of the actuator's power-on (its k = n − n0)
  bool act_restarted = false;
  engine::Network& net = hs.net_;
  engine::Kernel& k = hs.kernel_;
  const HandlerId sample_h = k.add_handler("sample", [&](std::uint64_t) {
    const OutputVec y = hs.sample();
    // A report the interface refuses is counted in the sensor's statistics.
    net.run_node(kSensor, [&]() { static_cast<void>(sensor->on_sample(net.node_clock(kSensor), y)); });
  });
  // The NEES (filters with a covariance: AK, AKx, AKl): the estimate x̂⁻_k of x(t_k) and P⁻_k of
  // the last computation, against the true state at t_k when command k is applied there (the
  // plant is at t_k then; a period whose command is late is not taken: the run is not moved).
  struct Pending {
    bool set = false;
    node::SequenceNumber k = 0;
    Vector<double, kN> xh{};
    Matrix<double, kN, kN> p{};
  } pending;
  const HandlerId compute_h = k.add_handler("compute", [&](std::uint64_t) {
    const Estimator before = ctrl->estimator();
    const std::uint32_t runs = ctrl->statistics().computations;
    net.run_node(kController, [&]() { ctrl->on_receive(net.node_clock(kController)); });
    hs.estimate(ctrl->last_k(), ctrl->estimator().estimate());
    if constexpr (kHasCovariance<Estimator>) {
      if (ctrl->statistics().computations != runs && hs.opt_faults_empty_) {
        pending = Pending{true, ctrl->last_k(), ctrl->estimator().estimate(), ctrl->estimator().filter().covariance()};
      }
    }
    if (hs.an_ && ctrl->statistics().computations != runs) {
      hs.an_->compute_sync(before, ctrl->estimator(), hs.ctx_.period_us(), hs.ref_.state(ctrl->last_k()),
                           hs.ref_.input(ctrl->last_k()), ctrl->last_command());
    }
  });
  // Each node's clock reads t − φ of its own offset (Scenario::sensor_clock_us): the actuator's
  // is the loop's phase (its timer below at kh + φ_a), the sensor reads t_k on its own clock.
  net.add_node(kSensor, "sensor", hs.clock_offset_of(hs.sc_.sensor_clock_us), [&]() {
    const McuInstant now = net.node_clock(kSensor);
    McuInstant at;
    if (!sensor->on_receive(now, at)) return;
    const std::int64_t wait_us = at - now;
    if (wait_us <= 0) {
      const OutputVec y = hs.sample();
      // Inside the sensor's run_node: routed afterwards (a refusal is counted by the sensor).
      static_cast<void>(sensor->on_sample(now, y));
    } else {
      k.schedule_in(engine::from_us(wait_us), EventClass::kSample, sample_h);
    }
  });
  net.add_node(kController, "controller", hs.clock_offset_of(hs.sc_.controller_clock_us),
               [&]() { hs.start_computation(compute_h); });
  net.add_node(kActuator, "actuator", hs.clock_offset_of(hs.sc_.actuator_clock_us), [&]() { act->on_receive(); });
  hs.route_leg(kActuator, kSensor, "as");
  hs.route_leg(kSensor, kController, "sc");
  hs.route_leg(kController, kActuator, "ca");
  net.arm_faults({{"sensor",
                   [&]() {
                     sensor.emplace(kController, late_us);
                     check_sensor();
                     hs.lose_inbox(kSensor);
                   }},
                  {"controller",
                   [&]() {
                     ctrl.emplace(kActuator, l, hs.u_min_, hs.u_max_, est, hs.ref_);
                     check_ctrl();
                     hs.lose_inbox(kController);
                   }},
                  {"actuator", [&]() {
                     act.emplace(kSensor, InputVec{});
                     check_act();
                     hs.lose_inbox(kActuator);
                     act_restarted = true;
                   }}});
  auto timer_h = std::make_shared<HandlerId>(0);
  *timer_h = k.add_handler("actuation", [&, timer_h](std::uint64_t n) {
    if (act_restarted) {  // the restarted actuator's first timer is its k = 0
      act_restarted = false;
      act_n0 = n;
    }
    net.run_node(kActuator, [&]() {
      const McuInstant next = net.node_clock(kActuator).plus(hs.ctx_.period_us());
      if (n == act_n0) {
        act->start(next);
      } else {
        act->on_timer(static_cast<node::SequenceNumber>(n - act_n0), next);
      }
      InputVec u;
      if (act->take_output(u)) {
        hs.apply(u);
        if (pending.set && pending.k == n - act_n0) {
          hs.add_nees(hs.plant_.state(), pending.xh, pending.p);
          pending.set = false;
        }
      }
    });
    const SimTime t_next = k.now() + hs.h_;
    if (t_next < hs.end_) k.schedule(t_next, EventClass::kActuation, *timer_h, n + 1);
  });
  k.schedule(SimTime{hs.offset_}, EventClass::kActuation, *timer_h, 0);  // at kh + φ_a (the loop's phase)
  RunResult r = hs.finish();
  r.late = act->statistics().late;
  r.saturated = ctrl->statistics().saturated;
  r.faults = ctrl->statistics().faults;
  r.counters = concat(concat(sync_sensor_counters(*sensor), sync_controller_counters(*ctrl)), actuator_counters(*act));
  return r;
}

}  // namespace

RunResult run_synchronized(Harness& hs, Approach a) {
  using HalfEst = node::HalfKalmanEstimator<Fmt, Structure, Disc>;
  using Pred = node::SampledStatePredictor<Fmt, Structure, Disc>;
  const Vector<double, kN> x0 = hs.ref_.state(0);
  const auto half = [&](NoiseModel noise) {
    HalfEst e(hs.design_, hs.disc_, noise);
    e.reset(x0, hs.design_.p0, InputVec{});
    return e;
  };
  switch (a) {
    case Approach::kA:
      return run_synchronized(hs, Pred(hs.disc_), 0);
    case Approach::kAK:
      return run_synchronized(hs, half(NoiseModel::kConstant), 0);
    case Approach::kAKx:
      return run_synchronized(hs, half(NoiseModel::kExact), 0);
    case Approach::kAKl:
      return run_synchronized(hs, half(NoiseModel::kConstant), hs.ctx_.worst_chain_us(hs.sc_));
    default:
      throw std::logic_error(std::string("ncs: ") + name(a) + " is not an actuation-synchronized loop");
  }
}

}  // namespace oneshot::ncs::loop
