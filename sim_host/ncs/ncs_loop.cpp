/// @file ncs_loop.cpp
/// @brief One run of study `ncs` on the engine (see ncs_loop.hpp).
#include "ncs_loop.hpp"

#include <cmath>
#include <functional>
#include <memory>
#include <optional>
#include <stdexcept>

#include "ncs_analytic.hpp"
#include "ncs_counters.hpp"
#include "ncs_cpu.hpp"
#include "ncs_live_nodes.hpp"
#include "oneshot/engine/can_traffic.hpp"
#include "oneshot/engine/continuous_plant.hpp"
#include "oneshot/engine/cpu.hpp"
#include "oneshot/engine/kernel.hpp"
#include "oneshot/engine/network.hpp"
#include "oneshot/host/host_network.hpp"
#include "oneshot/node/actuator_node.hpp"
#include "oneshot/node/controller_node.hpp"
#include "oneshot/node/held_measurement.hpp"
#include "oneshot/node/held_measurement_estimator.hpp"
#include "oneshot/node/message.hpp"
#include "oneshot/node/periodic_trigger.hpp"
#include "oneshot/node/sampling_sync_laws.hpp"
#include "oneshot/node/send_on_delta_trigger.hpp"
#include "oneshot/node/sensor_node.hpp"
#include "oneshot/node/sync_actuator_node.hpp"
#include "oneshot/node/sync_controller_node.hpp"
#include "oneshot/node/sync_estimators.hpp"
#include "oneshot/node/sync_sensor_node.hpp"
#include "oneshot/plant_structure.hpp"

namespace oneshot::ncs {
namespace {

using Board = host::HostNetwork;
using Structure = DenseStructure<kN, kM, kP>;
using Ref = node::SquareWaveReference<double, kN, kM>;
using Plant = engine::ContinuousPlant<kN, kM, kP, 1>;
using engine::Duration;
using engine::EventClass;
using engine::HandlerId;
using engine::SimTime;
using InputVec = Vector<double, kM>;
using OutputVec = Vector<double, kP>;

// The live run's addresses (ncs_live.hpp): the frame checks of ncs_live_nodes.hpp name them.
constexpr std::uint8_t kSensor = kLiveSensor;
constexpr std::uint8_t kController = kLiveController;
constexpr std::uint8_t kActuator = kLiveActuator;

/// What every loop shares: kernel, plant, network, set-point, noise and timing streams.
class Harness {
 public:
  Harness(const Context& ctx, Approach a, const Scenario& sc, std::uint64_t seed, const RunOptions& opt)
      : ctx_(ctx),
        approach_(a),
        sc_(sc),
        design_(ctx.controller_design(sc.noise_scale)),
        disc_(ctx.discretizer_model(sc.noise_scale)),
        kernel_(seed),
        plant_(plant_config(ctx, sc, noisy(a, opt)),
               engine::RandomStream(opt.noise_seed != 0 ? opt.noise_seed : seed, "process")),
        net_(kernel_),
        measurement_(opt.noise_seed != 0 ? opt.noise_seed : seed, "measurement"),
        compute_(kernel_.stream("compute")),
        ref_(reference(ctx, sc)),
        noisy_(noisy(a, opt)),
        h_(engine::from_us(ctx.period_us())),
        end_(engine::from_seconds(sc.duration_s, "ncs scenario duration")) {
    net_.set_faults(opt.faults);
    opt_faults_empty_ = opt.faults.empty();
    if (one_shot(a) && opt.analytic) throw std::invalid_argument(std::string("ncs: ") + name(a) + " has no analytic cost");
    if (opt.record_messages) net_.record_messages();
    if (!legs_from_file(sc) && !(sc.max_delay_ms * 1000 >= static_cast<double>(ctx.timing().leg_min_us))) {
      throw std::invalid_argument("ncs scenario " + sc.name + ": d must be at least 0.5 ms");
    }
    const auto chol = measurement_cholesky(design_);
    for (std::size_t i = 0; i < 3; ++i) r_chol_[i] = chol[i];
    const live::InputRange range = live::actuator_range(ctx);
    u_min_ = range.lo;
    u_max_ = range.hi;
    const Vector<double, kN> x0 = ref_.state(0);
    plant_.set_state(x0);
    plant_.set_reference(x0, ref_.input(0));
    if (opt.analytic) an_ = make_tracker(ctx, sc, a, design_, opt, x0, ref_.input(0));
    if (opt.trace_step_s > 0) plant_.record_trace(engine::from_seconds(opt.trace_step_s, "trace step"), kernel_.stream("trace"));
    // Set-point switches on the kh grid (before anything else at that instant but the plant).
    const HandlerId sw = kernel_.add_handler("setpoint", [this](std::uint64_t k) {
      advance();
      const auto kk = static_cast<node::SequenceNumber>(k);
      plant_.set_reference(ref_.state(kk), ref_.input(kk));
      if (an_) an_->set_reference(ref_.state(kk), ref_.input(kk));
    });
    const std::uint64_t half = half_wave_periods(ctx, sc);
    for (std::uint64_t k = half; SimTime{h_ * static_cast<std::int64_t>(k)} < end_; k += half) {
      kernel_.schedule(SimTime{h_ * static_cast<std::int64_t>(k)}, EventClass::kEnvironment, sw, k);
    }
    if (sc.controller_cpu && one_shot(a)) throw std::invalid_argument("ncs: the one-shot controller has no CPU model");
    if (sc.controller_cpu && !delay_free(a)) {  // τ_c from the schedule (ncs_cpu.hpp)
      cpu_ = std::make_unique<engine::cpu::Cpu>(kernel_, sc.controller_cpu->set);
      cpu_task_ = sc.controller_cpu->task;
      cpu_->on_job([this](const engine::cpu::CpuJob& j) {
        if (j.entity == cpu_task_ && !j.aborted) kernel_.schedule(kernel_.now(), EventClass::kCompute, computed_);
      });
      cpu_->start(end_);
    }
    const HandlerId end = kernel_.add_handler("end", [this](std::uint64_t) { advance(); });
    kernel_.schedule(end_, EventClass::kEnd, end);
    if (opt.analytic_mark_s > 0 && !an_) throw std::invalid_argument("an analytic mark needs an analytic run");
    if (an_ && opt.analytic_mark_s > 0) {  // observes only: the plant and tracker are not advanced
      const SimTime mark{engine::from_seconds(opt.analytic_mark_s, "analytic mark")};
      if (mark > end_) throw std::invalid_argument("the analytic mark is after the end of the run");
      const HandlerId at_mark = kernel_.add_handler("analytic mark", [this](std::uint64_t) {
        result_.analytic_at_mark = an_->cost_at(kernel_.now());
      });
      kernel_.schedule(mark, EventClass::kRecord, at_mark);
    }
  }

  static bool noisy(Approach a, const RunOptions& opt) { return !opt.noise_free && !opt.analytic && a != Approach::kI; }

  /// The plant (and the analytic tracker) at now.
  void advance() {
    plant_.advance_to(kernel_.now());
    if (an_) an_->flow_to(kernel_.now());
  }

  engine::LinkConfig leg(const char* name) const { return ncs::leg(ctx_, sc_, approach_, name); }

  /// Adds leg `name` to the network and remembers it for the run's link counters.
  engine::Link& add_leg(const char* name) {
    engine::Link& l = net_.add_link(leg(name));
    legs_.emplace_back(name, &l);
    return l;
  }

  /// Routes leg `name` from `source` to `destination`: over its CAN bus when the scenario puts
  /// it on one (not for the delay-free loops I, IK), else over a link.
  void route_leg(std::uint8_t source, std::uint8_t destination, const char* name) {
    leg_routes_.push_back({{source, destination}, name});
    const auto b = sc_.bus_legs.find(name);
    if (b == sc_.bus_legs.end() || delay_free(approach_)) {
      net_.route(source, destination, add_leg(name));
      return;
    }
    net_.route(source, destination, bus(b->second), b->second.id);
    bus_legs_.emplace_back(name, std::make_pair(source, destination));
  }

  /// The bus of `leg`, built with its background traffic on first use.
  engine::CanBus& bus(const BusLeg& leg) {
    for (const auto& [nm, b] : buses_)
      if (nm == leg.bus.name) return *b;
    engine::CanBus& b = net_.add_can_bus(leg.bus);
    buses_.emplace_back(leg.bus.name, &b);
    if (!leg.background.empty()) {
      traffic_.push_back(std::make_unique<engine::CanTraffic>(kernel_, b, leg.background, leg.offsets, end_));
    }
    return b;
  }

  /// A frame reached the controller: `compute_h` runs τ_c later, τ_c drawn (compute_time())
  /// or, on a CPU, the response of the job released now (the handler runs at its finish).
  void start_computation(HandlerId compute_h) {
    if (!cpu_) {
      kernel_.schedule_in(compute_time(), EventClass::kCompute, compute_h);
      return;
    }
    computed_ = compute_h;
    cpu_->release(cpu_task_);
  }

  /// τ_c of the next computation (whole µs), 0 for the delay-free loops.
  Duration compute_time() {
    if (delay_free(approach_)) return Duration{0};
    if (sc_.compute_us) return engine::from_us(compute_.uniform_int(sc_.compute_us->first, sc_.compute_us->second));
    return engine::from_us(compute_.uniform_int(ctx_.timing().compute_min_us, ctx_.timing().compute_max_us));
  }

  /// The plant at now and a sample y = C x + v.
  OutputVec sample() {
    advance();
    OutputVec y = plant_.output();
    if (noisy_) {
      const double n0 = measurement_.normal();
      const double n1 = measurement_.normal();
      y[0] += r_chol_[0] * n0;
      y[1] += r_chol_[1] * n0 + r_chol_[2] * n1;
    }
    const double t = engine::to_seconds(kernel_.now());
    const OutputVec clean = plant_.output();
    result_.samples.push_back(Point{t, {y[0], y[1]}});
    result_.sample_truth.push_back(Point{t, {clean[0], clean[1]}});
    if (an_) an_->sample(kernel_.now(), y);
    return y;
  }

  void apply(const InputVec& u) {
    advance();
    plant_.set_input(u);
    if (an_) an_->apply(u);
    ++result_.commands;
  }

  void estimate(node::SequenceNumber k, const Vector<double, kN>& x) {
    result_.estimates.push_back(Point{static_cast<double>(k) * engine::to_seconds(h_), {x[0], x[1]}});
  }

  /// Node `address` restarts: whatever its interface held is lost.
  void lose_inbox(std::uint8_t address) { net_.node(address).interface.inbox.clear(); }

  /// Runs the kernel to the end and collects the cost, trace and injected faults.
  RunResult finish() {
    kernel_.run_until(end_);
    result_.events = kernel_.events_run();
    result_.injected = net_.fault_counters();
    for (const engine::MessageRecord& m : net_.messages()) {
      for (const auto& [route, nm] : leg_routes_) {
        if (route != std::make_pair(m.source, m.destination)) continue;
        result_.messages.push_back(MessageEvent{nm, engine::to_seconds(m.sent), engine::to_seconds(m.arrival), m.lost,
                                                m.delivered});
      }
    }
    result_.cost = plant_.cost().total();
    for (const auto& [nm, l] : legs_) result_.links.emplace_back(nm, l->statistics());
    for (const auto& [nm, route] : bus_legs_) {
      const engine::BusRouteStatistics& st = net_.bus_route_statistics(route.first, route.second);
      engine::LinkStatistics ls;
      ls.sent = st.sent;
      ls.max_delay = st.max_delay;
      result_.links.emplace_back(nm, ls);
      result_.bus_legs.emplace_back(nm, st);
    }
    if (an_) an_->report(result_);
    if (cpu_) {
      CpuRunStats& c = result_.cpu;
      const engine::cpu::CpuTaskStats& st = cpu_->stats()[cpu_task_];
      c.present = true;
      c.jobs = st.finished;
      c.response_min = st.response_min;
      c.response_max = st.response_max;
      c.response_sum_us = st.response_sum_s * 1e6;
      c.deadline_misses = st.deadline_misses;
      for (std::size_t e = 0; e < cpu_->stats().size(); ++e) {
        c.busy += cpu_->stats()[e].busy;
        if (e != cpu_task_) c.other_misses += cpu_->stats()[e].deadline_misses;
      }
    }
    for (const auto& s : plant_.trace()) {
      const double t = engine::to_seconds(s.t);
      result_.truth.push_back(Point{t, {s.x[0], s.x[1]}});
      result_.setpoint.push_back(Point{t, {s.r[0], s.u[0]}});
    }
    return std::move(result_);
  }

  const Context& ctx_;
  Approach approach_;
  const Scenario& sc_;
  Design design_;
  Disc disc_;
  engine::Kernel kernel_;
  Plant plant_;
  engine::Network net_;
  engine::RandomStream measurement_;
  engine::RandomStream compute_;
  Ref ref_;
  bool noisy_;
  bool opt_faults_empty_ = true;
  Duration h_;
  SimTime end_;
  double r_chol_[3] = {};
  InputVec u_min_;
  InputVec u_max_;
  RunResult result_;
  std::unique_ptr<AnalyticTracker> an_;
  std::vector<std::pair<std::string, engine::Link*>> legs_;
  std::vector<std::pair<std::string, std::pair<std::uint8_t, std::uint8_t>>> bus_legs_;  ///< Name, route.
  std::vector<std::pair<std::string, engine::CanBus*>> buses_;
  std::vector<std::pair<std::pair<std::uint8_t, std::uint8_t>, std::string>> leg_routes_;  ///< Route, leg name.
  std::vector<std::unique_ptr<engine::CanTraffic>> traffic_;
  std::unique_ptr<engine::cpu::Cpu> cpu_;  ///< The controller's CPU (Scenario::controller_cpu).
  std::size_t cpu_task_ = 0;               ///< The controller's job in it.
  HandlerId computed_ = 0;                 ///< The loop's compute handler (set at each release).
};

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
  const HandlerId compute_h = k.add_handler("compute", [&](std::uint64_t) {
    const Estimator before = ctrl->estimator();
    const std::uint32_t runs = ctrl->statistics().computations;
    net.run_node(kController, [&]() { ctrl->on_receive(net.node_clock(kController)); });
    hs.estimate(ctrl->last_k(), ctrl->estimator().estimate());
    if (hs.an_ && ctrl->statistics().computations != runs) {
      hs.an_->compute_sync(before, ctrl->estimator(), hs.ctx_.period_us(), hs.ref_.state(ctrl->last_k()),
                           hs.ref_.input(ctrl->last_k()), ctrl->last_command());
    }
  });
  net.add_node(kSensor, "sensor", Duration{0}, [&]() {
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
  net.add_node(kController, "controller", Duration{0},
               [&]() { hs.start_computation(compute_h); });
  net.add_node(kActuator, "actuator", Duration{0}, [&]() { act->on_receive(); });
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
      if (act->take_output(u)) hs.apply(u);
    });
    const SimTime t_next = k.now() + hs.h_;
    if (t_next < hs.end_) k.schedule(t_next, EventClass::kActuation, *timer_h, n + 1);
  });
  k.schedule(SimTime{0}, EventClass::kActuation, *timer_h, 0);
  RunResult r = hs.finish();
  r.late = act->statistics().late;
  r.saturated = ctrl->statistics().saturated;
  r.faults = ctrl->statistics().faults;
  r.counters = concat(concat(sync_sensor_counters(*sensor), sync_controller_counters(*ctrl)), actuator_counters(*act));
  return r;
}

/// The sampling-synchronized baseline with law `law`; `saturated(law)` reads its count.
template <typename Law, typename Saturated>
RunResult run_sampling(Harness& hs, Law law, Saturated saturated) {
  using Trigger = node::PeriodicTrigger<double, kP>;
  using Sensor = node::SensorNode<Board, Trigger, double, kP>;
  using Ctrl = node::ControllerNode<Board, Law, double, kP, kM>;
  using Act = node::ActuatorNode<Board, double, kM>;
  std::optional<Sensor> sensor(std::in_place, kController, Trigger(1));
  std::optional<Ctrl> ctrl(std::in_place, kActuator, node::ControllerMode::kOnArrival, law);
  std::optional<Act> act(std::in_place, node::ActuatorMode::kOnArrival, InputVec{});
  const auto check_ctrl = [&]() { ctrl->expect_source(kSensor); };  // samples: finite (the plant is not clamped)
  const auto check_act = [&]() { live::check_commands(hs.ctx_, *act); };
  check_ctrl();
  check_act();
  std::uint64_t sensor_n0 = 0;  // sample index of the sensor's power-on (its sequence = n − n0)
  bool sensor_restarted = false;
  engine::Network& net = hs.net_;
  engine::Kernel& k = hs.kernel_;
  std::uint32_t samples = 0;  // the sequence number of the next sample (no restart in analytic runs)
  const HandlerId compute_h = k.add_handler("compute", [&](std::uint64_t) {
    const Law before = ctrl->law();
    net.run_node(kController, [&]() { ctrl->on_receive(net.node_clock(kController)); });
    if (hs.an_) hs.an_->compute_law(before, samples - 1);
  });
  net.add_node(kSensor, "sensor", Duration{0}, nullptr);
  net.add_node(kController, "controller", Duration{0},
               [&]() { hs.start_computation(compute_h); });
  net.add_node(kActuator, "actuator", Duration{0}, [&]() {
    act->on_receive();
    InputVec u;
    if (act->take_output(u)) hs.apply(u);
  });
  hs.route_leg(kSensor, kController, "sc");
  hs.route_leg(kController, kActuator, "ca");
  net.arm_faults({{"sensor",
                   [&]() {
                     sensor.emplace(kController, Trigger(1));
                     sensor_restarted = true;
                   }},
                  {"controller",
                   [&]() {
                     ctrl.emplace(kActuator, node::ControllerMode::kOnArrival, law);
                     check_ctrl();
                     hs.lose_inbox(kController);
                   }},
                  {"actuator", [&]() {
                     act.emplace(node::ActuatorMode::kOnArrival, InputVec{});
                     check_act();
                     hs.lose_inbox(kActuator);
                   }}});
  auto timer_h = std::make_shared<HandlerId>(0);
  *timer_h = k.add_handler("sample", [&, timer_h](std::uint64_t n) {
    if (sensor_restarted) {
      sensor_restarted = false;
      sensor_n0 = n;
    }
    const OutputVec y = hs.sample();
    ++samples;
    const auto seq = static_cast<node::SequenceNumber>(n - sensor_n0);
    net.run_node(kSensor, [&]() { sensor->on_sample(seq, net.node_clock(kSensor), y); });
    const SimTime t_next = k.now() + hs.h_;
    if (t_next < hs.end_) k.schedule(t_next, EventClass::kSample, *timer_h, n + 1);
  });
  k.schedule(SimTime{0}, EventClass::kSample, *timer_h, 0);
  RunResult r = hs.finish();
  r.saturated = saturated(ctrl->law());
  r.counters = concat(sampling_controller_counters(*ctrl), actuator_counters(*act));
  return r;
}

/// The one-shot law (OS, OSp, OSK), a ControllerNode plug-in in timer mode: at the timer of
/// period k (begin_period) the receiver's measurements of period k (the sample that arrived,
/// a silent sensor's held value with R̄, or none) correct x̂_{k|k−1}, the filter predicts to
/// (k+1)h with u_k (the command it sent for period k) and the command for period k+1 is
/// u_{k+1} = u_ref − L (x̂_{k+1|k} − x_ref) at period k+1's set-point, clamped (counted).
/// Periods without a computation (before the first arrival) are predicted over with the
/// held command.
class OneShotLaw {
 public:
  using Receiver = node::HeldMeasurementReceiver<double, kP>;
  using Estimator = node::HeldMeasurementEstimator<double, kN, kM, kP>;

  OneShotLaw(const Receiver& rx, const Estimator& est, const Matrix<double, kM, kN>& l, const InputVec& u_min,
             const InputVec& u_max, const Ref& ref)
      : rx_(rx), est_(est), l_(l), u_min_(u_min), u_max_(u_max), ref_(ref) {}

  /// The period whose timer runs the next computation.
  void begin_period(node::SequenceNumber k) { k_ = k; }

  [[nodiscard]] node::LawResult compute(const node::Message<node::VectorPayload<double, kP>>& m, bool fresh, McuInstant,
                                        InputVec& u) {
    if (fresh) {
      for (std::size_t i = 0; i < kP; ++i) static_cast<void>(rx_.on_packet(i, m.seq, m.payload.value[i]));
    }
    for (; node::seq_newer(k_, next_); ++next_) note(est_.predict(u_model_));  // periods not computed
    for (std::size_t i = 0; i < kP; ++i) {
      const node::HeldMeasurement<double> hm = rx_.measurement(i, k_);
      if (hm.present) note(est_.correct(i, hm.z, hm.r_bar));
    }
    corrected_ = est_.estimate();
    corrected_p_ = est_.covariance();
    note(est_.predict(u_model_));
    next_ = k_ + 1;
    u = ref_.input(k_ + 1) - l_ * (est_.estimate() - ref_.state(k_ + 1));
    if (node::saturate(u, u_min_, u_max_)) ++saturated_;
    u_model_ = u;
    return node::LawResult::kSend;
  }

  /// x̂_{k|k} of the last computation.
  const Vector<double, kN>& corrected() const { return corrected_; }
  /// Its covariance P_{k|k}.
  const Matrix<double, kN, kN>& corrected_covariance() const { return corrected_p_; }
  /// Commands clamped to the actuator's range.
  std::uint32_t saturated() const { return saturated_; }
  /// Filter steps whose status was not kOk (singular or reset).
  std::uint32_t faults() const { return faults_; }

 private:
  void note(Status st) {
    if (st != Status::kOk) ++faults_;
  }
  Receiver rx_;
  Estimator est_;
  Matrix<double, kM, kN> l_;
  InputVec u_min_;
  InputVec u_max_;
  Ref ref_;
  node::SequenceNumber k_ = 0;
  node::SequenceNumber next_ = 0;  // the period x̂ is the prior of
  InputVec u_model_{};             // the command taken as applied in period next_
  Vector<double, kN> corrected_{};
  Matrix<double, kN, kN> corrected_p_{};
  std::uint32_t saturated_ = 0;
  std::uint32_t faults_ = 0;
};

/// The one-shot loop (ncs_model.hpp kOneShotApproaches): sensor on its timer at kh under
/// send-on-delta (OSK: every sample, the time rule at n_t = 1), controller on its timer at
/// kh + φ taking the frames that arrived by then and sending τ_c later, actuator on its timer
/// applying at (k+1)h the command stamped k+1 (else holding the last one: late, counted).
RunResult run_one_shot(Harness& hs, Approach a) {
  using Trigger = node::SendOnDeltaTrigger<double, kP>;
  using Sensor = node::SensorNode<Board, Trigger, double, kP>;
  using Ctrl = node::ControllerNode<Board, OneShotLaw, double, kP, kM>;
  using Act = node::ActuatorNode<Board, double, kM>;
  const Scenario& sc = hs.sc_;
  const std::int64_t h_us = hs.ctx_.period_us();
  if (!(sc.controller_phase_us > 0 && sc.controller_phase_us < h_us)) {
    throw std::invalid_argument("ncs one-shot loop: the controller's phase must be in (0, h)");
  }
  if (!hs.opt_faults_empty_) throw std::invalid_argument("ncs one-shot loop: no fault injection");
  Vector<double, kP> delta{};
  std::uint32_t n_t[kP] = {};
  std::uint32_t sensor_n_t = 1;  // OSK: the time rule sends every sample
  if (a != Approach::kOSK) {
    if (sc.sod_delta.size() != kP) throw std::invalid_argument("ncs one-shot loop: OS and OSp need one delta per output");
    for (std::size_t i = 0; i < kP; ++i) {
      delta[i] = sc.sod_delta[i];
      n_t[i] = sc.sod_time_steps;
    }
    sensor_n_t = sc.sod_time_steps;
  }
  Vector<double, kP> r_diag;
  for (std::size_t i = 0; i < kP; ++i) r_diag[i] = hs.design_.r(i, i);
  OneShotLaw::Receiver rx(delta, r_diag, n_t, a == Approach::kOS ? node::SilencePolicy::kHeld : node::SilencePolicy::kPredictOnly);
  // Q_d at the scenario's noise scale s (the plant's process noise is s·Q_c; the design's qd_h is at s = 1).
  OneShotLaw::Estimator est(hs.design_.phi_h, hs.design_.gamma_h, hs.design_.qd_h * sc.noise_scale, hs.design_.c);
  const Vector<double, kN> x0 = hs.ref_.state(0);
  est.reset(x0, hs.design_.p0);
  Sensor sensor(kController, Trigger(delta, sensor_n_t));
  Ctrl ctrl(kActuator, node::ControllerMode::kOnTimer, OneShotLaw(rx, est, hs.design_.l, hs.u_min_, hs.u_max_, hs.ref_));
  ctrl.expect_source(kSensor);
  // A send-on-delta sensor may stay silent for any number of periods: its next sample is not a
  // sequence jump (the frame checks' default window is 4096 periods).
  ctrl.set_sequence_window(1U << 30, node::kDefaultReacquireFrames);
  Act act(node::ActuatorMode::kOnTimer, InputVec{});
  live::check_commands(hs.ctx_, act);
  engine::Network& net = hs.net_;
  engine::Kernel& k = hs.kernel_;
  std::vector<Vector<double, kN>> truth;  // x(kh) per sample k
  double nees_sum = 0;
  std::uint32_t nees_n = 0;
  net.add_node(kSensor, "sensor", Duration{0}, nullptr);
  net.add_node(kController, "controller", Duration{0}, nullptr);  // frames wait for its timer
  net.add_node(kActuator, "actuator", Duration{0}, [&]() { act.on_receive(); });
  hs.route_leg(kSensor, kController, "sc");
  hs.route_leg(kController, kActuator, "ca");
  // Computation of period k, τ_c after its timer: the law on what the timer took in.
  const HandlerId compute_h = k.add_handler("compute", [&](std::uint64_t n) {
    const auto kk = static_cast<node::SequenceNumber>(n);
    const std::uint32_t runs = ctrl.statistics().computations;
    ctrl.law().begin_period(kk);
    net.run_node(kController, [&]() { ctrl.on_timer(net.node_clock(kController), kk + 1); });
    if (ctrl.statistics().computations == runs || n >= truth.size()) return;
    const Vector<double, kN>& xh = ctrl.law().corrected();
    const Matrix<double, kN, kN>& p = ctrl.law().corrected_covariance();
    const double e0 = truth[n][0] - xh[0];
    const double e1 = truth[n][1] - xh[1];
    const double det = p(0, 0) * p(1, 1) - p(0, 1) * p(1, 0);
    hs.estimate(kk, xh);
    if (!(det > 0)) return;  // a singular P (noise scale 0): no NEES term
    static_assert(kN == 2, "the NEES below inverts a 2 x 2 covariance in closed form");
    // eᵀ P⁻¹ e with P⁻¹ = [[p11, −p01], [−p10, p00]] / det
    const double q = (e0 * e0 * p(1, 1) - e0 * e1 * (p(0, 1) + p(1, 0)) + e1 * e1 * p(0, 0)) / det;
    if (!std::isfinite(q)) return;
    nees_sum += q;
    ++nees_n;
  });
  auto ctrl_h = std::make_shared<HandlerId>(0);
  *ctrl_h = k.add_handler("controller timer", [&, ctrl_h](std::uint64_t n) {
    net.run_node(kController, [&]() { ctrl.on_receive(net.node_clock(kController)); });
    k.schedule_in(hs.compute_time(), EventClass::kCompute, compute_h, n);
    const SimTime t_next = k.now() + hs.h_;
    if (t_next < hs.end_) k.schedule(t_next, EventClass::kCompute, *ctrl_h, n + 1);
  });
  auto sample_h = std::make_shared<HandlerId>(0);
  *sample_h = k.add_handler("sample", [&, sample_h](std::uint64_t n) {
    const OutputVec y = hs.sample();
    truth.push_back(hs.plant_.state());
    net.run_node(kSensor, [&]() { sensor.on_sample(static_cast<node::SequenceNumber>(n), net.node_clock(kSensor), y); });
    const SimTime t_next = k.now() + hs.h_;
    if (t_next < hs.end_) k.schedule(t_next, EventClass::kSample, *sample_h, n + 1);
  });
  auto act_h = std::make_shared<HandlerId>(0);
  *act_h = k.add_handler("actuation", [&, act_h](std::uint64_t n) {
    net.run_node(kActuator, [&]() {
      act.on_timer(static_cast<node::SequenceNumber>(n));
      InputVec u;
      if (act.take_output(u)) hs.apply(u);
    });
    const SimTime t_next = k.now() + hs.h_;
    if (t_next < hs.end_) k.schedule(t_next, EventClass::kActuation, *act_h, n + 1);
  });
  k.schedule(SimTime{0}, EventClass::kSample, *sample_h, 0);
  if (SimTime{engine::from_us(sc.controller_phase_us)} < hs.end_) {
    k.schedule(SimTime{engine::from_us(sc.controller_phase_us)}, EventClass::kCompute, *ctrl_h, 0);
  }
  if (SimTime{hs.h_} < hs.end_) k.schedule(SimTime{hs.h_}, EventClass::kActuation, *act_h, 1);  // u_0: the initial input
  RunResult r = hs.finish();
  r.late = act.statistics().late;
  r.saturated = ctrl.law().saturated();
  r.faults = ctrl.law().faults();
  r.nees = nees_n > 0 ? nees_sum / nees_n : 0;
  r.nees_steps = nees_n;
  r.sent = sensor.statistics().sends;
  r.sampled = sensor.statistics().samples;
  r.counters = concat(sampling_controller_counters(ctrl), actuator_counters(act));
  return r;
}

}  // namespace

RunResult run(const Context& ctx, Approach a, const Scenario& sc, std::uint64_t seed, const RunOptions& options) {
  RunResult r = run_approach(ctx, a, sc, seed, options);
  if (options.analytic) refuse_nonlinear_runs(r);
  return r;
}

RunResult run_approach(const Context& ctx, Approach a, const Scenario& sc, std::uint64_t seed, const RunOptions& options) {
  Harness hs(ctx, a, sc, seed, options);
  const Vector<double, kN> x0 = hs.ref_.state(0);
  using HalfEst = node::HalfKalmanEstimator<Fmt, Structure, Disc>;
  using Pred = node::SampledStatePredictor<Fmt, Structure, Disc>;
  const auto half = [&](NoiseModel noise) {
    HalfEst e(hs.design_, hs.disc_, noise);
    e.reset(x0, hs.design_.p0, InputVec{});
    return e;
  };
  using Feedback = node::StateFeedbackLaw<double, kN, kM, Ref>;
  using Kalman = node::PeriodicKalmanLaw<Fmt, Structure, Ref>;
  using Compensated = node::DelayCompensatedLaw<double, kN, kM, Ref>;
  switch (a) {
    case Approach::kA:
      return run_synchronized(hs, Pred(hs.disc_), 0);
    case Approach::kAK:
      return run_synchronized(hs, half(NoiseModel::kConstant), 0);
    case Approach::kAKx:
      return run_synchronized(hs, half(NoiseModel::kExact), 0);
    case Approach::kAKl:
      return run_synchronized(hs, half(NoiseModel::kConstant), ctx.worst_chain_us(sc));
    case Approach::kI:
    case Approach::kS:
      return run_sampling(hs, Feedback{hs.design_.l, hs.u_min_, hs.u_max_, hs.ref_},
                          [](const Feedback& f) { return f.saturated; });
    case Approach::kSK:
    case Approach::kIK: {
      Kalman law(hs.design_, NoiseModel::kConstant, hs.u_min_, hs.u_max_, hs.ref_);
      law.filter().reset(x0, hs.design_.p0, InputVec{});
      return run_sampling(hs, law, [](Kalman& f) { return f.saturated(); });
    }
    case Approach::kSPlus: {
      const SplitGain g = delay_compensated_split(ctx, ctx.mean_tau_io_us(sc));
      Compensated law{g.lx, g.lu, hs.u_min_, hs.u_max_, hs.ref_};
      return run_sampling(hs, law, [](const Compensated& f) { return f.saturated; });
    }
    case Approach::kOS:
    case Approach::kOSp:
    case Approach::kOSK:
      return run_one_shot(hs, a);
  }
  throw std::logic_error("ncs: unknown approach");
}

}  // namespace oneshot::ncs
