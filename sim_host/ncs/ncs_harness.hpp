/// @file ncs_harness.hpp
/// @brief What every loop of study `ncs` shares (private to ncs_loop.cpp, ncs_sync_loop.cpp
///        and ncs_one_shot_loop.cpp): the Harness (kernel, plant, network, set-point, noise and
///        timing streams, the controller's CPU); the loops' aliases, addresses and World in
///        ncs_world.hpp, a NEES term in ncs_nees.hpp, a CPU's run figures in ncs_cpu_stats.hpp.
#pragma once

#include <algorithm>
#include <cmath>
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "ncs_analytic.hpp"
#include "ncs_cache_pools.hpp"
#include "ncs_cpu.hpp"
#include "ncs_cpu_stats.hpp"
#include "ncs_live_nodes.hpp"
#include "ncs_loop.hpp"
#include "ncs_nees.hpp"
#include "ncs_world.hpp"
#include "oneshot/engine/can_traffic.hpp"
#include "oneshot/engine/continuous_plant.hpp"
#include "oneshot/engine/cpu.hpp"
#include "oneshot/engine/kernel.hpp"
#include "oneshot/engine/network.hpp"
#include "oneshot/engine/psd_math.hpp"
#include "oneshot/engine/plant_cache_pool.hpp"
#include "oneshot/host/host_network.hpp"
#include "oneshot/node/message.hpp"
#include "oneshot/plant_structure.hpp"

namespace oneshot::ncs::loop {

/// What every loop shares: kernel, plant, network, set-point, noise and timing streams, for
/// a plant of shape S (ncs_model.hpp; the analytic tracker on the board's shape only).
template <typename S>
class BasicHarness {
 public:
  static constexpr bool kBoard = std::is_same_v<S, BoardShape>;  ///< The board's shape (2, 1, 2).
  using Design = typename S::Design;                              ///< The controller design.
  using Disc = typename S::Disc;                                  ///< The discretizer.
  using Structure = DenseStructure<S::n, S::m, S::p>;             ///< Dense matrices.
  using Ref = BasicSetpointReference<S::n, S::m>;                 ///< The set-point.
  using Plant = engine::ContinuousPlant<S::n, S::m, S::p, 1>;     ///< The continuous plant.
  using InputVec = Vector<double, S::m>;                          ///< u.
  using OutputVec = Vector<double, S::p>;                         ///< y.
  using StateVec = Vector<double, S::n>;                          ///< x.

  /// A loop on its own engine, or (`world`, `on`) one of several loops on a shared one: its
  /// random streams then named "<loop>/<source>", its nodes at the loop's addresses.
  BasicHarness(const Context& ctx, Approach a, const Scenario& sc, std::uint64_t seed, const RunOptions& opt,
               World* world = nullptr, const LoopOnBus* on = nullptr)
      : ctx_(ctx),
        approach_(a),
        sc_(sc),
        design_(ctx.controller_design_of<S>(sc.noise_scale)),
        disc_(ctx.discretizer_model_of<S>(sc.noise_scale)),
        prefix_(on != nullptr && !on->name.empty() ? on->name + "/" : std::string()),
        own_world_(world == nullptr ? std::make_unique<World>(seed) : nullptr),
        world_(world == nullptr ? *own_world_ : *world),
        kernel_(world_.kernel),
        plant_(plant_config_of<S>(ctx, sc, noisy(a, opt)),
               engine::RandomStream(opt.noise_seed != 0 ? opt.noise_seed : seed, prefix_ + "process"), caches(opt)),
        net_(world_.net),
        measurement_(opt.noise_seed != 0 ? opt.noise_seed : seed, prefix_ + "measurement"),
        compute_(kernel_.stream(prefix_ + "compute")),
        ref_(reference_of<S>(ctx, sc)),
        noisy_(noisy(a, opt)),
        h_(engine::from_us(ctx.period_us())),
        offset_(engine::from_us(on != nullptr ? on->clock_offset_us : loop_phase_us(a, sc))),
        end_(offset_ + engine::from_seconds(sc.duration_s, "ncs scenario duration")) {
    if (offset_ < Duration{0} || offset_ >= h_) {
      throw std::invalid_argument("ncs: a loop's clock offset is in [0, h) (" + std::to_string(offset_.count() / 1000) + " us)");
    }
    if (own_world_ || end_ > world_.end) world_.end = end_;
    // The timer node's φ is the loop's phase (in [0, h): above); the others' |φ| < h.
    for (const std::int64_t phi : {sc.sensor_clock_us, sc.controller_clock_us, sc.actuator_clock_us}) {
      if (phi != 0 && (on != nullptr || one_shot(a) || engine::from_us(phi < 0 ? -phi : phi) >= h_)) {
        throw std::invalid_argument("ncs: a node's clock offset is within (-h, h) in a loop run alone, not one-shot (" +
                                    std::to_string(phi) + " us)");
      }
    }
    on_bus_ = on != nullptr;
    if (opt.analytic && (sc.sensor_clock_us != 0 || sc.controller_clock_us != 0 || sc.actuator_clock_us != 0)) {
      throw std::invalid_argument("ncs: the analytic tracker runs the nodes on one clock (no clock offsets)");
    }
    if (on != nullptr) {
      sensor_at_ = on->sensor;
      controller_at_ = on->controller;
      actuator_at_ = on->actuator;
    }
    if (own_world_ || !opt.faults.empty()) net_.set_faults(opt.faults);  // a shared run has none
    opt_faults_empty_ = opt.faults.empty();
    if (one_shot(a) && opt.analytic) throw std::invalid_argument(std::string("ncs: ") + name(a) + " has no analytic cost");
    // The tracker and the trace take the run's time; a loop shifted by φ runs on its own.
    if (offset_ != Duration{0} && (opt.analytic || opt.trace_step_s > 0)) {
      throw std::invalid_argument("ncs: a loop with a clock offset has no analytic cost and no trace");
    }
    if (opt.record_messages) net_.record_messages();
    if (!legs_from_file(sc) && !(sc.max_delay_ms * 1000 >= static_cast<double>(ctx.timing().leg_min_us))) {
      throw std::invalid_argument("ncs scenario " + sc.name + ": d must be at least 0.5 ms");
    }
    r_chol_ = engine::psd_cholesky<S::p>(design_.r);
    for (std::size_t j = 0; j < S::m; ++j) {  // the actuator's range (live::actuator_range() on the board)
      u_min_[j] = design_.actuator.u_min[j];  // the design's (a padded input's −1: ncs_shape_design.cpp)
      u_max_[j] = j < m_ ? ctx.design().u_max[j] : 1.0;  // a padded input: [−1, 1] holds its 0
    }
    const StateVec x0 = ref_.state(0);
    plant_.set_state(x0);
    plant_.set_reference(x0, ref_.input(0));
    if constexpr (kBoard) {
      if (opt.analytic && !ctx.board()) {
        throw std::invalid_argument("ncs: --analytic runs the board's plant (n = 2, m = 1, p = 2, C = I) only: its tracker is 2-state");
      }
      if (opt.analytic) an_ = make_tracker(ctx, sc, a, design_, opt, x0, ref_.input(0));
    } else if (opt.analytic) {
      throw std::invalid_argument("ncs: --analytic runs the board's plant (n = 2, m = 1, p = 2) only: its tracker is 2-state");
    }
    if (opt.trace_step_s > 0) plant_.record_trace(engine::from_seconds(opt.trace_step_s, "trace step"), kernel_.stream(prefix_ + "trace"));
    // Set-point switches on the kh grid (before anything else at that instant but the plant).
    const HandlerId sw = kernel_.add_handler("setpoint", [this](std::uint64_t k) {
      advance();
      const auto kk = static_cast<node::SequenceNumber>(k);
      plant_.set_reference(ref_.state(kk), ref_.input(kk));
      tracker([&](auto& t) { t.set_reference(ref_.state(kk), ref_.input(kk)); });
    });
    const auto k_end = static_cast<std::uint64_t>(((end_ - offset_).count() + h_.count() - 1) / h_.count());
    for (std::uint64_t k : ref_.switches(k_end)) {
      kernel_.schedule(SimTime{offset_ + h_ * static_cast<std::int64_t>(k)}, EventClass::kEnvironment, sw, k);
    }
    if (sc.controller_cpu && !delay_free(a)) {  // τ_c from the schedule (ncs_cpu.hpp)
      cpu_ = std::make_unique<engine::cpu::Cpu>(kernel_, sc.controller_cpu->set);
      cpu_task_ = sc.controller_cpu->task;
      cpu_->on_job([this](const engine::cpu::CpuJob& j) {
        if (j.entity == cpu_task_ && !j.aborted) kernel_.schedule(kernel_.now(), EventClass::kCompute, computed_, j.index);
      });
      cpu_->start(end_);
    }
    if (sc.sensor_cpu && !delay_free(a)) {  // the sampling job (ncs_cpu.hpp); the loop sets its callbacks
      if (a != Approach::kS && a != Approach::kSK) {
        throw std::invalid_argument(std::string("ncs: the sensor on a CPU runs with S and SK only, not ") + name(a));
      }
      if (opt.analytic) throw std::invalid_argument("ncs: no analytic cost with the sensor on a CPU");
      sensor_cpu_ = std::make_unique<engine::cpu::Cpu>(kernel_, sc.sensor_cpu->set);
      sensor_task_ = sc.sensor_cpu->task;
      sensor_cpu_->start(end_);
    }
    const HandlerId end = kernel_.add_handler("end", [this](std::uint64_t) { advance(); });
    kernel_.schedule(end_, EventClass::kEnd, end);
    if (opt.analytic_mark_s > 0 && !an_) throw std::invalid_argument("an analytic mark needs an analytic run");
    if (an_ && opt.analytic_mark_s > 0) {  // observes only: the plant and tracker are not advanced
      const SimTime mark{engine::from_seconds(opt.analytic_mark_s, "analytic mark")};
      if (mark > end_) throw std::invalid_argument("the analytic mark is after the end of the run");
      const HandlerId at_mark = kernel_.add_handler("analytic mark", [this](std::uint64_t) {
        tracker([&](auto& t) { result_.analytic_at_mark = t.cost_at(kernel_.now()); });
      });
      kernel_.schedule(mark, EventClass::kRecord, at_mark);
    }
  }

  /// Node `role`'s clock offset for the engine (its clock reads t + offset = t − φ: Scenario::sensor_clock_us);
  /// 0 in a run of several loops (their clocks are the loop's phase alone).
  Duration clock_offset_of(std::int64_t phi_us) const { return on_bus_ ? Duration{0} : -engine::from_us(phi_us); }

  /// Whether a run of `a` under `opt` draws process and measurement noise.
  static bool noisy(Approach a, const RunOptions& opt) { return !opt.noise_free && !opt.analytic && a != Approach::kI; }

  /// The sweep's shared plant caches of shape S (RunOptions::caches; none: the run's own).
  static engine::PlantCachePool<S::n, S::m + 1>* caches(const RunOptions& opt) {
    return opt.caches != nullptr ? opt.caches->template pool<S>() : nullptr;
  }

  /// Calls fn(tracker) when the run has an analytic tracker (the board's shape only).
  template <typename Fn>
  void tracker(Fn&& fn) {
    if constexpr (kBoard) {
      if (an_) fn(*an_);
    }
  }

  /// The first two entries of `v` (the second 0 for a vector of one) at time `t_s`: a row of
  /// the run's records (Point).
  template <std::size_t K>
  static Point point(double t_s, const Vector<double, K>& v) {
    if constexpr (K > 1) {
      return Point{t_s, {v[0], v[1]}};
    } else {
      return Point{t_s, {v[0], 0.0}};
    }
  }

  /// The plant (and the analytic tracker) at now: on the plant's time, the loop's (now − φ,
  /// the loop's clock offset), held at the loop's end in a run that goes on for a later loop.
  void advance() {
    const SimTime t = std::min(std::max(kernel_.now(), offset_), end_);
    plant_.advance_to(t - offset_);
    tracker([&](auto& tr) { tr.flow_to(t); });
  }

  /// Leg `name`'s link of this scenario and approach.
  engine::LinkConfig leg(const char* name) const {
    engine::LinkConfig c = ncs::leg(ctx_, sc_, approach_, name);
    c.name = prefix_ + c.name;  // its streams "link/<loop>/<leg>/..." in a run of several loops
    return c;
  }

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
    for (const auto& [nm, b] : world_.buses)
      if (nm == leg.bus.name) return *b;
    engine::CanBus& b = net_.add_can_bus(leg.bus);
    world_.buses.emplace_back(leg.bus.name, &b);
    if (!leg.background.empty()) {
      world_.traffic.push_back(std::make_unique<engine::CanTraffic>(kernel_, b, leg.background, leg.offsets, world_.end));
    }
    return b;
  }

  /// A frame reached the controller (or the one-shot controller's timer fired): `compute_h`
  /// runs τ_c later with argument `arg`, τ_c drawn (compute_time()) or, on a CPU, the response
  /// of the job released now (the handler runs at its finish, with the job's index: the
  /// number of releases before it, which is `arg` when the loop releases once per `arg`).
  void start_computation(HandlerId compute_h, std::uint64_t arg = 0) {
    if (!cpu_) {
      kernel_.schedule_in(compute_time(), EventClass::kCompute, compute_h, arg);
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

  /// Adds the measurement noise v = L n, n ~ N(0, I) drawn in output order, to the first p
  /// (the plant's real outputs: a padded output draws nothing) entries of `y`.
  template <std::size_t K>
  void add_measurement_noise(Vector<double, K>& y) {
    Vector<double, S::p> n;
    for (std::size_t i = 0; i < S::p && i < p_; ++i) n[i] = measurement_.normal();
    for (std::size_t i = 0; i < S::p && i < K && i < p_; ++i) {
      double v = 0;
      for (std::size_t j = 0; j <= i; ++j) v += r_chol_(i, j) * n[j];
      y[i] += v;
    }
  }

  /// The plant at now and a sample y = C x + v.
  OutputVec sample() {
    advance();
    OutputVec y = plant_.output();
    if (noisy_) add_measurement_noise(y);
    const double t = engine::to_seconds(kernel_.now());
    result_.samples.push_back(point(t, y));
    result_.sample_truth.push_back(point(t, plant_.output()));
    tracker([&](auto& tr) { tr.sample(kernel_.now(), y); });
    return y;
  }

  /// The plant at now and the state it sends: x (the reference loop I: no noise), or for S
  /// (C = I, p = n: y = x + v) x with the measurement noise of sample(), drawn alike.
  StateVec sample_state() {
    advance();
    StateVec x = plant_.state();
    if (noisy_) {
      if (!ctx_.identity_output()) throw std::logic_error("ncs: a noisy state sample needs C = I");
      add_measurement_noise(x);
    }
    const double t = engine::to_seconds(kernel_.now());
    result_.samples.push_back(point(t, x));
    result_.sample_truth.push_back(point(t, plant_.output()));
    tracker([&](auto& tr) { tr.sample(kernel_.now(), x); });
    return x;
  }

  /// The plant at now, then input `u` from now on (a command applied).
  void apply(const InputVec& u) {
    advance();
    plant_.set_input(u);
    tracker([&](auto& t) { t.apply(u); });
    ++result_.commands;
  }

  /// Records estimate x̂ of period k (at kh).
  void estimate(node::SequenceNumber k, const StateVec& x) {
    result_.estimates.push_back(point(static_cast<double>(k) * engine::to_seconds(h_), x));
  }

  /// Adds e_kᵀ P⁻¹ e_k, e_k = x − x̂, of the estimate `xh` with covariance `p` of the true state
  /// `x` to the run's NEES (RunResult::nees); nothing when P is singular (noise scale 0) or the
  /// value is not finite.
  /// Over the plant's real n states only (a padded state's P is 0).
  void add_nees(const StateVec& x, const StateVec& xh, const Matrix<double, S::n, S::n>& p) {
    double q = 0;
    if (!nees_term<S::n>(x, xh, p, n_, q)) return;
    if (!std::isfinite(q)) return;
    nees_sum_ += q;
    ++nees_n_;
  }

  /// Node `address` restarts: whatever its interface held is lost.
  void lose_inbox(std::uint8_t address) { net_.node(address).interface.inbox.clear(); }

  /// Runs the kernel to the end and collects the cost, trace and injected faults.
  RunResult finish() {
    if (inner_) {
      inner_();  // the next loop of a shared run: it runs the kernel
    } else {
      kernel_.run_until(world_.end);
    }
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
    result_.nees = nees_n_ > 0 ? nees_sum_ / nees_n_ : 0;
    result_.nees_steps = nees_n_;
    for (const auto& [nm, l] : legs_) result_.links.emplace_back(nm, l->statistics());
    for (const auto& [nm, route] : bus_legs_) {
      const engine::BusRouteStatistics& st = net_.bus_route_statistics(route.first, route.second);
      engine::LinkStatistics ls;
      ls.sent = st.sent;
      ls.max_delay = st.max_delay;
      result_.links.emplace_back(nm, ls);
      result_.bus_legs.emplace_back(nm, st);
    }
    tracker([&](auto& t) { t.report(result_); });
    if (cpu_) cpu_stats(*cpu_, cpu_task_, result_.cpu);
    if (sensor_cpu_) cpu_stats(*sensor_cpu_, sensor_task_, result_.sensor_cpu);
    for (const auto& s : plant_.trace()) {
      const double t = engine::to_seconds(s.t);
      result_.truth.push_back(point(t, s.x));
      result_.setpoint.push_back(Point{t, {s.r[0], s.u[0]}});
    }
    return std::move(result_);
  }

  const Context& ctx_;
  std::size_t n_ = ctx_.states();   ///< The plant's real n (≤ S::n: the rest padded).
  std::size_t m_ = ctx_.inputs();   ///< Its real m.
  std::size_t p_ = ctx_.outputs();  ///< Its real p.
  Approach approach_;
  const Scenario& sc_;
  Design design_;
  Disc disc_;
  std::string prefix_;               ///< "" or "<loop>/": the loop's random streams' prefix.
  std::unique_ptr<World> own_world_;  ///< The engine of a loop run alone.
  World& world_;                     ///< The engine the loop runs on.
  engine::Kernel& kernel_;
  Plant plant_;
  engine::Network& net_;
  engine::RandomStream measurement_;
  engine::RandomStream compute_;
  Ref ref_;
  bool noisy_;
  bool opt_faults_empty_ = true;
  Duration h_;
  Duration offset_;  ///< The loop's clock offset φ (LoopOnBus::clock_offset_us): its timer at kh + φ.
  SimTime end_;      ///< The loop's end: φ + the scenario's duration.
  bool on_bus_ = false;  ///< One loop of several on one engine (LoopOnBus).
  Matrix<double, S::p, S::p> r_chol_{};  ///< Lower Cholesky factor of R (the measurement noise).
  InputVec u_min_;
  InputVec u_max_;
  RunResult result_;
  double nees_sum_ = 0;        ///< Σ e_kᵀ P_k⁻¹ e_k (add_nees()).
  std::uint32_t nees_n_ = 0;   ///< Its terms.
  std::unique_ptr<AnalyticTracker> an_;
  std::vector<std::pair<std::string, engine::Link*>> legs_;
  std::vector<std::pair<std::string, std::pair<std::uint8_t, std::uint8_t>>> bus_legs_;  ///< Name, route.
  std::vector<std::pair<std::pair<std::uint8_t, std::uint8_t>, std::string>> leg_routes_;  ///< Route, leg name.
  std::uint8_t sensor_at_ = kSensor;          ///< The sensor's address.
  std::uint8_t controller_at_ = kController;  ///< The controller's.
  std::uint8_t actuator_at_ = kActuator;      ///< The actuator's.
  std::function<void()> inner_;  ///< Set in a shared run but for its last loop: runs the next loop (finish()).
  std::unique_ptr<engine::cpu::Cpu> cpu_;  ///< The controller's CPU (Scenario::controller_cpu).
  std::size_t cpu_task_ = 0;               ///< The controller's job in it.
  HandlerId computed_ = 0;                 ///< The loop's compute handler (set at each release).
  std::unique_ptr<engine::cpu::Cpu> sensor_cpu_;  ///< The sensor's CPU (Scenario::sensor_cpu).
  std::size_t sensor_task_ = 0;                   ///< The sensor's job in it.
};

/// The harness of the board's plant (every approach).
using Harness = BasicHarness<BoardShape>;

/// The one-shot loop OS, OSp or OSK `a` on `hs` (ncs_one_shot_loop.cpp).
RunResult run_one_shot(Harness& hs, Approach a);

/// The actuation-synchronized loop A, AK, AKx or AKl `a` on `hs` (ncs_sync_loop.cpp).
RunResult run_synchronized(Harness& hs, Approach a);

}  // namespace oneshot::ncs::loop
