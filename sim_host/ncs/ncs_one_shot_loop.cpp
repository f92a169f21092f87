/// @file ncs_one_shot_loop.cpp
/// @brief The one-shot loops OS, OSp, OSK of study `ncs` on the engine (see ncs_loop.hpp).
#include <cmath>
#include <memory>
#include <stdexcept>
#include <vector>

#include "ncs_counters.hpp"
#include "ncs_harness.hpp"
#include "oneshot/node/actuator_node.hpp"
#include "oneshot/node/controller_node.hpp"
#include "oneshot/node/held_measurement.hpp"
#include "oneshot/node/held_measurement_estimator.hpp"
#include "oneshot/node/mtm_trigger.hpp"
#include "oneshot/node/send_on_delta_trigger.hpp"
#include "oneshot/node/sensor_node.hpp"

namespace oneshot::ncs::loop {
namespace {

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

/// The one-shot sensor's rule: send-on-delta (OS, OSp; OSK: every sample through its time
/// rule) or MTM (Scenario::sensor_mtm), one SensorNode type for both.
class OneShotTrigger {
 public:
  using Sod = node::SendOnDeltaTrigger<double, kP>;
  using Mtm = node::MtmTrigger<double, kP>;
  /// Send-on-delta.
  explicit OneShotTrigger(const Sod& sod) : sod_(sod), mtm_(0, 0, 0, 0), mtm_on_(false) {}
  /// MTM.
  explicit OneShotTrigger(const Mtm& mtm) : sod_(Vector<double, kP>{}, 0), mtm_(mtm), mtm_on_(true) {}
  /// The rule's decision for sample k with value y.
  node::SendCause evaluate(node::SequenceNumber k, const OutputVec& y) const {
    return mtm_on_ ? mtm_.evaluate(k, y) : sod_.evaluate(k, y);
  }
  /// A send of sample k with value y.
  void on_sent(node::SequenceNumber k, const OutputVec& y) {
    if (mtm_on_) {
      mtm_.on_sent(k, y);
    } else {
      sod_.on_sent(k, y);
    }
  }
  /// The set-point changes at sample k (MTM sends k_ref,max samples later; send-on-delta ignores it).
  void notify_reference_change(node::SequenceNumber k) {
    if (mtm_on_) mtm_.notify_reference_change(k);
  }

 private:
  Sod sod_;
  Mtm mtm_;
  bool mtm_on_;
};

}  // namespace

/// The one-shot loop (ncs_model.hpp kOneShotApproaches): sensor on its timer at kh under
/// send-on-delta (OSK: every sample, the time rule at n_t = 1), controller on its timer at
/// kh + φ taking the frames that arrived by then and sending τ_c later, actuator on its timer
/// applying at (k+1)h the command stamped k+1 (else holding the last one: late, counted).
/// With a controller CPU (Scenario::controller_cpu) the timer releases the controller's job
/// (periodic at h, phase φ) and the command is computed and sent at its finish.
RunResult run_one_shot(Harness& hs, Approach a) {
  using Sensor = node::SensorNode<Board, OneShotTrigger, double, kP>;
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
  const bool mtm = a != Approach::kOSK && sc.sensor_mtm;
  if (mtm) {
    // Silent under MTM with σ = 0: |ȳ_i − y_i| ≤ √δ, the held value of send-on-delta at δy = √δ
    // with the time rule n_t = k_max. With σ > 0 the bound depends on y: OS (held) cannot run.
    if (a == Approach::kOS && sc.mtm_sigma != 0) {
      throw std::invalid_argument("ncs one-shot loop: OS under MTM needs sigma = 0 (a held value within +-sqrt(delta))");
    }
    for (std::size_t i = 0; i < kP; ++i) {
      delta[i] = std::sqrt(sc.mtm_delta);
      n_t[i] = sc.mtm_k_max;
    }
  } else if (a != Approach::kOSK) {
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
  // Φ(h), Γ(h), Q_d(h): the design's exact triple, or the study file's table discretizer's.
  std::size_t slot = 0;
  while (kOneShotApproaches[slot] != a) ++slot;
  const OneShotTriple* table = sc.one_shot_triples[slot].get();
  OneShotLaw::Estimator est(table != nullptr ? table->phi : hs.design_.phi_h, table != nullptr ? table->gamma : hs.design_.gamma_h,
                            (table != nullptr ? table->qd : hs.design_.qd_h) * sc.noise_scale, hs.design_.c);
  const Vector<double, kN> x0 = hs.ref_.state(0);
  est.reset(x0, hs.design_.p0);
  Sensor sensor(kController, mtm ? OneShotTrigger(OneShotTrigger::Mtm(sc.mtm_sigma, sc.mtm_delta, sc.mtm_k_max, sc.mtm_k_ref_max))
                                 : OneShotTrigger(OneShotTrigger::Sod(delta, sensor_n_t)));
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
    hs.estimate(kk, xh);
    hs.add_nees(truth[n], xh, ctrl.law().corrected_covariance());  // x(kh) against x̂_{k|k}, P_{k|k}
  });
  auto ctrl_h = std::make_shared<HandlerId>(0);
  *ctrl_h = k.add_handler("controller timer", [&, ctrl_h](std::uint64_t n) {
    net.run_node(kController, [&]() { ctrl.on_receive(net.node_clock(kController)); });
    hs.start_computation(compute_h, n);  // τ_c drawn, or the controller job's response on its CPU
    const SimTime t_next = k.now() + hs.h_;
    if (t_next < hs.end_) k.schedule(t_next, EventClass::kCompute, *ctrl_h, n + 1);
  });
  auto sample_h = std::make_shared<HandlerId>(0);
  *sample_h = k.add_handler("sample", [&, sample_h](std::uint64_t n) {
    const OutputVec y = hs.sample();
    truth.push_back(hs.plant_.state());
    const auto kk = static_cast<node::SequenceNumber>(n);
    if (mtm && n > 0 && hs.ref_.setpoint(kk) != hs.ref_.setpoint(kk - 1)) sensor.trigger().notify_reference_change(kk);
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
  r.sent = sensor.statistics().sends;
  r.sampled = sensor.statistics().samples;
  r.counters = concat(sampling_controller_counters(ctrl), actuator_counters(act));
  return r;
}

}  // namespace oneshot::ncs::loop
