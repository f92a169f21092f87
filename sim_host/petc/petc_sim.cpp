/// @file petc_sim.cpp
/// @brief The petc closed loop on the engine and its per-run metrics.
#include "petc_sim.hpp"

#include <algorithm>
#include <cmath>
#include <memory>
#include <optional>
#include <stdexcept>

#include "oneshot/app/petc_pil.hpp"
#include "oneshot/engine/discrete_plant.hpp"
#include "oneshot/engine/frame_faults.hpp"
#include "oneshot/engine/kernel.hpp"
#include "oneshot/engine/sequenced_frame.hpp"
#include "oneshot/node/disturbance_observer.hpp"
#include "oneshot/node/interlaced_controller.hpp"
#include "oneshot/node/mtm_trigger.hpp"
#include "oneshot/node/packet_buffer.hpp"
#include "petc_frames.hpp"
#include "petc_hold_controller.hpp"
#include "petc_numre_controller.hpp"

namespace oneshot::sim::petc {

namespace {

constexpr std::size_t kPlantStates = 12;
constexpr std::size_t kPlantOnly = 10;
using Dob = node::DisturbanceObserver<double, kDobSections, kDobMaxDelay>;
using node::SendCause;

Law make_law(const PetcSetup& s) {
  node::InterlacedConfig<double, 1, 2> cfg;
  cfg.feedthrough = s.mrci.feedthrough;
  cfg.ratio = static_cast<std::uint32_t>(s.mrci.ratio);
  cfg.sample_at_update = s.opt.sample_at_update;
  std::size_t f = 0, sl = 0;
  for (const MrciMode& m : s.mrci.modes) {
    if (m.slow)
      cfg.slow[sl++] = {m.residue, m.pole};
    else
      cfg.fast[f++] = {m.residue, m.pole};
  }
  return Law(cfg);
}

Dob make_dob(const PetcSetup& s) { return Dob(dob_config(s)); }

Vector<double, 1> scalar(double x) {
  Vector<double, 1> v;
  v[0] = x;
  return v;
}

/// Longest gap between sends (and from the last send to K).
std::size_t longest_silence(const std::vector<std::uint32_t>& sends, std::size_t steps) {
  std::size_t best = 0;
  for (std::size_t i = 1; i < sends.size(); ++i) best = std::max<std::size_t>(best, sends[i] - sends[i - 1]);
  if (!sends.empty()) best = std::max<std::size_t>(best, steps - sends.back());
  return best;
}

template <typename Ctrl>
std::vector<double> simulate(const PetcSetup& s, const CaseSpec& c, std::uint64_t seed, Ctrl& ctrl, RunTrace* tr,
                             FaultRun* fr) {
  const std::size_t steps = s.opt.steps;
  const EstimatorModel& m = s.plant.augmented;
  engine::DiscretePlantConfig<kPlantStates, 1, 1, 1> pc;
  pc.phi = model_matrix<kPlantStates, kPlantStates>(m.a, "the plant's Phi");
  pc.gamma = model_matrix<kPlantStates, 1>(m.b, "the plant's Gamma");
  pc.c = model_matrix<1, kPlantStates>(m.c, "the plant's C");
  const Matrix<double, kPlantStates, 1> bw = model_matrix<kPlantStates, 1>(m.b_w, "the plant's B_w");
  pc.q = (bw * bw.transposed()) * m.w;
  pc.period = std::chrono::microseconds(s.plant.file.period_us);
  pc.process_noise = c.noise;
  const Matrix<double, 1, kPlantStates> c_bar = model_matrix<1, kPlantStates>(m.c_bar, "the plant's C_bar");
  const double sigma_v = std::sqrt(m.v);

  engine::Kernel kernel(seed);
  engine::DiscretePlant<kPlantStates, 1, 1, 1> plant(pc, kernel.stream("process"));
  engine::RandomStream meas = kernel.stream("measurement");
  const engine::SimTime end = engine::SimTime{pc.period * static_cast<std::int64_t>(steps)};
  engine::attach_discrete_plant(kernel, plant, end);

  Trigger sensor(c.sigma_s, c.delta_s, static_cast<std::uint32_t>(kHorizon), 0);
  sensor.notify_reference_change(0);  // the unit step at k = 0 (eq. 8 with delay 0)
  node::PacketBuffer<double, kHorizon> actuator(0.0);
  const bool always = c.controller == ControllerKind::kTts;

  std::vector<std::uint32_t> sensor_sends, actuator_sends;
  std::size_t sensor_safety = 0, controller_safety = 0, reference_sends = 0, held_beyond = 0;
  std::uint32_t n_max = 0;
  std::uint64_t macs_max = 0;
  double inbox_y = 0;
  std::vector<double> y_true(steps, 0.0), d(steps, 0.0), d_hat(steps, 0.0);
  if (tr) *tr = RunTrace{};

  // Frame faults (faulted runs only: the clean run registers and draws nothing more).
  const bool faulted = fr != nullptr && !fr->spec.empty();
  std::optional<engine::LinkFaults> sc_faults, ca_faults;
  std::vector<std::vector<std::uint8_t>> sc_frames, ca_frames;  // delivered by index
  FrameReceiver ctrl_rx(s.y_range), act_rx(s.u_range);
  std::optional<Ctrl> ctrl_power_on;
  engine::FaultCounters restarts;
  if (faulted) {
    sc_faults.emplace(fr->spec, "sc", engine::kSequencedFrameLayout, seed);
    ca_faults.emplace(fr->spec, "ca", engine::kSequencedFrameLayout, seed);
    if (!engine::restart_instants(fr->spec, "controller").empty()) ctrl_power_on.emplace(ctrl);
  }
  const auto period_now = [&] { return static_cast<std::uint32_t>(kernel.now().count() / pc.period.count()); };
  // Sends `bytes` through `faults`: the frame and the copies it gains, all at `now` (no delay, no loss).
  const auto send = [&](engine::LinkFaults& faults, std::vector<std::uint8_t> bytes, engine::EventClass cls,
                        engine::HandlerId h, std::vector<std::vector<std::uint8_t>>& frames) {
    std::vector<std::vector<std::uint8_t>> extra;
    faults.apply(kernel.now(), bytes, extra);
    extra.insert(extra.begin(), std::move(bytes));
    for (auto& f : extra) {
      kernel.schedule(kernel.now(), cls, h, frames.size());
      frames.push_back(std::move(f));
    }
  };

  engine::HandlerId on_rx = kernel.add_handler("actuator receive", [&](std::uint64_t k) {
    // Without faults packets arrive in order: an older one is kept out (the one in force stays).
    static_cast<void>(actuator.accept(static_cast<std::uint32_t>(k), ctrl.packet()));
    plant.set_input(scalar(actuator.value(static_cast<std::uint32_t>(k))));
  });
  engine::HandlerId on_rx_frame{};
  if (faulted)
    on_rx_frame = kernel.add_handler("actuator frame", [&](std::uint64_t i) {
      std::uint32_t k = 0;
      double u[kHorizon + 1];
      if (!act_rx.receive(ca_frames[i], k, u, kHorizon + 1, period_now())) return;
      static_cast<void>(actuator.accept(k, u));  // act_rx passed it: never older than the one in force
      plant.set_input(scalar(actuator.value(k)));
    });
  const auto arrive = [&](std::uint32_t kk, double y) {
    const SendCause cause = ctrl.arrive(kk, y);
    n_max = std::max(n_max, ctrl.multiplicity());
    macs_max = std::max(macs_max, ctrl.last_macs());
    if (tr) {
      tr->multiplicity.push_back(ctrl.multiplicity());
      ctrl.record_state(*tr);
    }
    if (cause == SendCause::kNone) return;
    if (cause == SendCause::kTime) ++controller_safety;
    actuator_sends.push_back(kk);
    if (faulted)
      send(*ca_faults, engine::encode_sequenced_frame(kk, ctrl.packet(), kHorizon + 1), engine::EventClass::kActuation,
           on_rx_frame, ca_frames);
    else
      kernel.schedule(kernel.now(), engine::EventClass::kActuation, on_rx, kk);
  };
  engine::HandlerId on_arrival = kernel.add_handler("controller arrival", [&](std::uint64_t k) {
    arrive(static_cast<std::uint32_t>(k), inbox_y);
  });
  engine::HandlerId on_arrival_frame{};
  if (faulted)
    on_arrival_frame = kernel.add_handler("controller frame", [&](std::uint64_t i) {
      std::uint32_t k = 0;
      double y = 0;
      if (ctrl_rx.receive(sc_frames[i], k, &y, 1, period_now())) arrive(k, y);
    });
  engine::HandlerId on_sample = kernel.add_handler("sensor sample", [&](std::uint64_t k) {
    const auto kk = static_cast<std::uint32_t>(k);
    const double y = plant.output()[0];
    const double v = meas.normal();  // drawn every period (common random numbers)
    const double ym = y + (c.noise ? sigma_v * v : 0.0);
    y_true[k] = y;
    d[k] = (c_bar * plant.state())(0, 0);
    if (tr) {
      tr->y_true.push_back(y);
      tr->y_meas.push_back(ym);
    }
    Vector<double, 1> yv;
    yv[0] = ym;
    const SendCause cause = always ? SendCause::kPeriodic : sensor.evaluate(kk, yv);
    if (cause == SendCause::kNone) return;
    sensor.on_sent(kk, yv);
    if (cause == SendCause::kTime) ++sensor_safety;
    if (cause == SendCause::kReference) ++reference_sends;
    sensor_sends.push_back(kk);
    if (faulted) {
      send(*sc_faults, engine::encode_sequenced_frame(kk, &ym, 1), engine::EventClass::kDelivery, on_arrival_frame,
           sc_frames);
      return;
    }
    inbox_y = ym;
    kernel.schedule(kernel.now(), engine::EventClass::kDelivery, on_arrival, k);
  });
  engine::HandlerId on_record = kernel.add_handler("record", [&](std::uint64_t k) {
    d_hat[k] = ctrl.d_hat(static_cast<std::uint32_t>(k));
    if (tr) tr->u.push_back(plant.input()[0]);
  });
  auto period_id = std::make_shared<engine::HandlerId>(0);
  *period_id = kernel.add_handler("actuator period", [&, period_id](std::uint64_t k) {
    const auto kk = static_cast<std::uint32_t>(k);
    plant.set_input(scalar(actuator.value(kk)));
    if (actuator.exhausted(kk)) ++held_beyond;
    kernel.schedule(kernel.now(), engine::EventClass::kSample, on_sample, k);
    kernel.schedule(kernel.now(), engine::EventClass::kRecord, on_record, k);
    if (k + 1 < steps) kernel.schedule(kernel.now() + pc.period, engine::EventClass::kActuation, *period_id, k + 1);
  });
  kernel.schedule(engine::SimTime{0}, engine::EventClass::kActuation, *period_id, 0);
  if (faulted) {  // restarts: the node rebuilt as at power-on (the receivers forget their last frame)
    const engine::HandlerId restart = kernel.add_handler("restart", [&](std::uint64_t node) {
      restarts.count(engine::FaultClause::Kind::kRestart);
      if (node == 0) {
        sensor = Trigger(c.sigma_s, c.delta_s, static_cast<std::uint32_t>(kHorizon), 0);
      } else if (node == 1) {
        ctrl.restart_as(*ctrl_power_on);
        ctrl_rx.forget();
      } else {
        actuator = node::PacketBuffer<double, kHorizon>(0.0);
        act_rx.forget();
      }
    });
    const std::vector<std::string> nodes = petc_node_names();
    for (std::size_t i = 0; i < nodes.size(); ++i)
      for (const engine::SimTime t : engine::restart_instants(fr->spec, nodes[i]))
        if (t < end) kernel.schedule(t, engine::EventClass::kEnvironment, restart, i);
  }
  kernel.run_until(end);
  if (fr != nullptr) {
    double e2 = 0;
    for (double y : y_true) e2 += (s.opt.reference - y) * (s.opt.reference - y);
    fr->tracking_error = std::sqrt(e2);
    fr->events = kernel.events_run();
    sim::RunFaultCounts& n = fr->counts;
    n = sim::RunFaultCounts{};
    if (faulted) {
      engine::FaultCounters inj = restarts;
      inj += sc_faults->counters();
      inj += ca_faults->counters();
      n.injected = static_cast<double>(inj.injected());
      for (const FrameCounts& rc : {ctrl_rx.counts(), act_rx.counts()}) {
        n.corrupt += rc.corrupt;
        n.refused_non_finite += rc.refused_non_finite;
        n.refused_out_of_range += rc.refused_out_of_range;
        n.refused_sequence += rc.refused_sequence;
        n.stale += rc.stale;
      }
      n.estimator_resets = ctrl.estimator_resets();
    }
  }

  if (tr) {
    tr->d = d;
    tr->d_hat = d_hat;
    tr->sensor_sent.assign(steps, 0);
    tr->actuator_sent.assign(steps, 0);
    for (auto k : sensor_sends) tr->sensor_sent[k] = 1;
    for (auto k : actuator_sends) tr->actuator_sent[k] = 1;
  }
  double isep2 = 0, derr2 = 0, d2 = 0;
  for (std::size_t k = 0; k < steps; ++k) {
    const double dy = y_true[k] - (k < s.y_tts.size() ? s.y_tts[k] : 0.0);
    isep2 += dy * dy;
    derr2 += (d[k] - d_hat[k]) * (d[k] - d_hat[k]);
    d2 += d[k] * d[k];
  }
  const double kk = static_cast<double>(steps);
  const double uc = static_cast<double>(sensor_sends.size()) / kk;
  const double ua = static_cast<double>(actuator_sends.size()) / kk;
  const double ne = s.ise > 0 ? std::sqrt(isep2) / s.ise : 0.0;
  return {uc,
          ua,
          uc * (1.0 - s.mrci.cs),
          ne,
          0.45 * uc + 0.45 * ua + 0.1 * ne,
          static_cast<double>(sensor_sends.size()),
          static_cast<double>(actuator_sends.size()),
          static_cast<double>(longest_silence(sensor_sends, steps)),
          static_cast<double>(longest_silence(actuator_sends, steps)),
          static_cast<double>(sensor_safety),
          static_cast<double>(controller_safety),
          static_cast<double>(reference_sends),
          static_cast<double>(n_max),
          static_cast<double>(ctrl.macs()),
          static_cast<double>(macs_max),
          s.ise,
          std::sqrt(isep2),
          std::sqrt(derr2 / kk),
          std::sqrt(d2 / kk),
          static_cast<double>(held_beyond)};
}

}  // namespace

node::DisturbanceObserverConfig<double, kDobSections, kDobMaxDelay> dob_config(const PetcSetup& s) {
  node::DisturbanceObserverConfig<double, kDobSections, kDobMaxDelay> cfg;
  cfg.q = {s.dob.q.b0, s.dob.q.b1, s.dob.q.b2, s.dob.q.a1, s.dob.q.a2};
  for (std::size_t i = 0; i < s.dob.inverse.size(); ++i) {
    const Biquad& b = s.dob.inverse[i];
    cfg.inverse[i] = {b.b0, b.b1, b.b2, b.a1, b.a2};
  }
  cfg.inverse_gain = s.dob.inverse_gain;
  cfg.delay = static_cast<std::uint32_t>(s.dob.delay);
  return cfg;
}

const std::vector<std::string>& metric_names() {
  static const std::vector<std::string> names = {
      "U_c", "U_a", "C_c", "N_E", "GPI", "sensor_packets", "actuator_packets", "longest_silence_sensor",
      "longest_silence_actuator", "sensor_safety_fires", "controller_safety_fires", "reference_sends", "N_max",
      "macs", "macs_max_arrival", "ISE", "ISEP", "d_error_rms", "d_rms", "held_beyond_horizon"};
  return names;
}

std::vector<CaseSpec> default_cases() {
  const double s1 = 1e-5, c1 = 1.32e-2, s2 = 1e-7, c2 = 1e-4;
  return {
      {"1", "TTS", ControllerKind::kTts, ObserverKind::kAugmented, false, 0, 0, 0, 0},
      {"2", "PETC, no NUMRE", ControllerKind::kHold, ObserverKind::kAugmented, false, s1, s1, c1, c1},
      {"3", "PETC + NUMRE, noise-free", ControllerKind::kNumre, ObserverKind::kAugmented, false, s1, s1, c1, c1},
      {"4", "+ noise and disturbance", ControllerKind::kNumre, ObserverKind::kAugmented, true, s1, s1, c1, c1},
      {"5", "narrow thresholds", ControllerKind::kNumre, ObserverKind::kAugmented, true, s2, s2, c2, c2},
      {"6", "plant-only NUMRE + DOB", ControllerKind::kNumre, ObserverKind::kDob, true, s2, s2, c2, c2},
      {"6'", "plant-only NUMRE + ESO", ControllerKind::kNumre, ObserverKind::kEso, true, s2, s2, c2, c2},
  };
}

std::vector<std::string> petc_link_names() { return {"sc", "ca"}; }
std::vector<std::string> petc_node_names() { return {"sensor", "controller", "actuator"}; }

std::vector<double> run_case(const PetcSetup& s, const CaseSpec& c, std::uint64_t seed, RunTrace* trace,
                             FaultRun* faults) {
  if (faults != nullptr) engine::check_fault_targets(faults->spec, petc_link_names(), petc_node_names());
  const Law law = make_law(s);
  const Trigger trig(c.sigma_c, c.delta_c, static_cast<std::uint32_t>(kHorizon), 0);
  const double r = s.opt.reference;
  if (c.controller != ControllerKind::kNumre) {
    HoldController h(law, trig, c.controller == ControllerKind::kTts, r);
    return simulate(s, c, seed, h, trace, faults);
  }
  switch (c.observer) {
    case ObserverKind::kAugmented: {
      NumreController<kPlantStates, node::ModelDisturbance<double>, app::petc::HddStructure> n(
          s.node_model.model, s.opt.frozen_noise, law, {}, trig, r);
      return simulate(s, c, seed, n, trace, faults);
    }
    case ObserverKind::kDob: {
      NumreController<kPlantOnly, Dob> n(s.plant_only, s.opt.frozen_noise, law, make_dob(s), trig, r);
      return simulate(s, c, seed, n, trace, faults);
    }
    case ObserverKind::kEso: {
      NumreController<kPlantOnly + 1, node::ModelDisturbance<double>> n(s.eso, s.opt.frozen_noise, law, {}, trig, r);
      return simulate(s, c, seed, n, trace, faults);
    }
  }
  throw std::logic_error("petc: unknown observer");
}

PetcSetup make_setup(const PetcOptions& opt) {
  PetcSetup s;
  s.opt = opt;
  s.plant = load_plant_facts(opt.plant_path.empty() ? default_plant_path() : opt.plant_path);
  if (opt.sigma_w >= 0) s.plant.augmented.w = opt.sigma_w * opt.sigma_w;
  if (opt.sigma_v >= 0) s.plant.augmented.v = opt.sigma_v * opt.sigma_v;
  if (s.plant.augmented.a.rows != kPlantStates || s.plant.phi_p.rows != kPlantOnly)
    throw std::invalid_argument("petc: the study is compiled for a 10-state plant with 2 disturbance states");
  s.node_model = block_diagonal_model(s.plant.augmented, 2, kPlantOnly);
  if (opt.steps == 0 || opt.steps > 1000000) throw std::invalid_argument("petc: --steps must lie in 1 … 1000000");
  s.mrci = brief_mrci(opt.ratio);
  if (s.mrci.fast_count != 1 || s.mrci.slow_count != 2)
    throw std::invalid_argument("petc: the ratio m = " + std::to_string(opt.ratio) +
                                " gives a split other than 2 slow + 1 fast modes, which the node is compiled for");
  s.dob = design_dob(s.plant, opt.dob_cutoff_hz);
  if (s.dob.inverse.size() > kDobSections || s.dob.delay > kDobMaxDelay || s.dob.delay == 0)
    throw std::invalid_argument("petc: the DOB needs more sections or delay than compiled in");
  s.var_d = disturbance_variance(s.plant, opt.steps);
  double mean = 0;
  for (double x : s.var_d) mean += x;
  mean /= static_cast<double>(s.var_d.size());
  s.plant_only = plant_only_model(s.plant, mean);
  s.eso = eso_model(s.plant, s.var_d.back() / static_cast<double>(opt.steps));
  // Case 1 (deterministic): the TTS output and ISE.
  RunTrace t;
  s.y_tts.clear();
  static_cast<void>(run_case(s, default_cases()[0], 1, &t));
  s.y_tts = t.y_true;
  double ise2 = 0;
  for (double y : s.y_tts) ise2 += (opt.reference - y) * (opt.reference - y);
  s.ise = std::sqrt(ise2);
  double y_peak = std::fabs(opt.reference), u_peak = 0;
  for (double y : s.y_tts) y_peak = std::max(y_peak, std::fabs(y));
  for (double u : t.u) u_peak = std::max(u_peak, std::fabs(u));
  s.y_range = 10 * y_peak;
  s.u_range = 10 * u_peak;
  return s;
}

}  // namespace oneshot::sim::petc
