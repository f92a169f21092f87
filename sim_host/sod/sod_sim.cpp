/// @file sod_sim.cpp
/// @brief One run of the send-on-delta study (see sod_sim.hpp).
#include "sod_sim.hpp"

#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>

#include "oneshot/engine/discrete_plant.hpp"
#include "oneshot/engine/kernel.hpp"
#include "oneshot/engine/link.hpp"
#include "oneshot/engine/random_stream.hpp"
#include "oneshot/engine/sequenced_frame.hpp"
#include "oneshot/node/held_measurement.hpp"
#include "oneshot/node/held_measurement_estimator.hpp"
#include "oneshot/node/periodic_trigger.hpp"
#include "oneshot/node/send_on_delta_trigger.hpp"

namespace oneshot::sod {
namespace {

using V1 = Vector<double, 1>;

/// A node's rule: send-on-delta (plain or modified) or periodic.
struct NodeRule {
  SenderKind kind;
  node::SendOnDeltaTrigger<double, 1> sod;
  node::PeriodicTrigger<double, 1> periodic;

  node::SendCause evaluate(node::SequenceNumber k, const V1& y) const {
    return kind == SenderKind::kPeriodic ? periodic.evaluate(k, y) : sod.evaluate(k, y);
  }
  void on_sent(node::SequenceNumber k, const V1& y) {
    if (kind == SenderKind::kPeriodic) periodic.on_sent(k, y); else sod.on_sent(k, y);
  }
};

NodeRule make_rule(const RunConfig& cfg, std::size_t i) {
  V1 d;
  d[0] = cfg.delta_y[i];
  const std::uint32_t n_t = cfg.sender == SenderKind::kModifiedSod ? cfg.n_t[i] : 0;
  return NodeRule{cfg.sender, node::SendOnDeltaTrigger<double, 1>(d, n_t),
                  node::PeriodicTrigger<double, 1>(cfg.every[i])};
}

void check(const RunConfig& cfg) {
  if (!(cfg.loss >= 0 && cfg.loss <= 1)) throw std::invalid_argument("sod: loss rate must lie in [0, 1]");
  if (cfg.steps < 1 || cfg.steps > (std::int64_t{1} << 31)) throw std::invalid_argument("sod: steps must lie in [1, 2^31]");
  for (std::size_t i = 0; i < kNodes; ++i) {
    if (!(cfg.delta_y[i] >= 0) || !std::isfinite(cfg.delta_y[i])) throw std::invalid_argument("sod: delta_y must be finite and >= 0");
    if (cfg.every[i] == 0) throw std::invalid_argument("sod: periodic sender needs every >= 1");
  }
  if (!(cfg.p0 > 0)) throw std::invalid_argument("sod: P(0) must be positive");
  engine::check_fault_targets(cfg.faults, sod_link_names(), {});  // frame faults only: no node restarts
}

}  // namespace

RunResult simulate_run(const SodModel& model, const RunConfig& cfg, std::uint64_t seed, RunTrace* trace) {
  check(cfg);
  static const char* const kNodeNames[kNodes] = {"node1", "node2"};
  const engine::Duration period{static_cast<std::int64_t>(model.period_us) * 1000};
  const engine::SimTime end{period.count() * cfg.steps};
  engine::Kernel kernel(seed);

  auto pc = engine::make_discrete_config<kStates, kInputs, kNodes, 1>(model.discrete, "sod");
  pc.process_noise = cfg.noise;
  engine::DiscretePlant<kStates, kInputs, kNodes, 1> plant(pc, kernel.stream("process"));
  Vector<double, kInputs> u;
  u[0] = cfg.amplitude;
  plant.set_input(u);
  engine::attach_discrete_plant(kernel, plant, end);

  std::optional<engine::RandomStream> meas[kNodes];
  std::optional<engine::Link> link[kNodes];
  NodeRule rule[kNodes] = {make_rule(cfg, 0), make_rule(cfg, 1)};
  for (std::size_t i = 0; i < kNodes; ++i) {
    meas[i].emplace(kernel.stream(engine::stream_name("measurement", kNodeNames[i])));
    engine::LinkConfig lc;
    lc.name = kNodeNames[i];
    lc.loss.kind = engine::LossModel::Kind::kBernoulli;  // drawn even at ξ = 0: the stream stays aligned
    lc.loss.p = cfg.loss;
    link[i].emplace(lc, seed);
  }

  // Frame faults (faulted runs only: the clean run registers nothing more, bit-identical).
  const bool faulted = !cfg.faults.empty();
  std::optional<engine::LinkFaults> faults[kNodes];
  if (faulted)
    for (std::size_t i = 0; i < kNodes; ++i) faults[i].emplace(cfg.faults, kNodeNames[i], engine::kSequencedFrameLayout, seed);
  std::vector<std::vector<std::uint8_t>> frames;  // delivered by "sod frame" (arg: index << 1 | node)

  Vector<double, kNodes> dy, r;
  for (std::size_t i = 0; i < kNodes; ++i) {
    dy[i] = cfg.delta_y[i];
    r[i] = model.r_diag[i];
  }
  const std::uint32_t n_t_rx[kNodes] = {cfg.sender == SenderKind::kModifiedSod ? cfg.n_t[0] : 0u,
                                        cfg.sender == SenderKind::kModifiedSod ? cfg.n_t[1] : 0u};
  node::HeldMeasurementReceiver<double, kNodes> rx(
      dy, r, n_t_rx, cfg.filter == FilterKind::kHeld ? node::SilencePolicy::kHeld : node::SilencePolicy::kPredictOnly);
  node::HeldMeasurementEstimator<double, kStates, kInputs, kNodes> est(model.a_d, model.b_d, model.q_d, model.c);
  Matrix<double, kStates, kStates> p0;
  for (std::size_t i = 0; i < kStates; ++i) p0(i, i) = cfg.p0;
  est.reset(Vector<double, kStates>{}, p0);

  RunResult res;
  double pending_y[kNodes] = {};
  std::uint32_t lost_run[kNodes] = {};   // packets sent since the last arrival (all lost)
  std::uint32_t last_d[kNodes] = {};
  const std::int64_t tail_from = static_cast<std::int64_t>(std::ceil(cfg.tail_from_s / model.period_s() - 1e-9));
  std::int64_t tail_count = 0;
  std::uint8_t cause_now[kNodes] = {};
  double y_now[kNodes] = {};

  const engine::HandlerId deliver = kernel.add_handler("sod delivery", [&](std::uint64_t arg) {
    const std::size_t i = arg & 1u;
    // The ideal link delivers the sensor's finite samples: refused only if not finite (counted).
    static_cast<void>(rx.on_packet(i, static_cast<node::SequenceNumber>(arg >> 1), pending_y[i]));
    lost_run[i] = 0;
  });
  std::int64_t step_now = 0;
  engine::HandlerId deliver_frame{};
  if (faulted) {
    deliver_frame = kernel.add_handler("sod frame", [&](std::uint64_t arg) {
      const std::size_t i = arg & 1u;
      node::SequenceNumber k = 0;
      double y = 0;
      switch (engine::decode_sequenced_frame(frames[arg >> 1], k, &y, 1)) {
        case engine::SequencedFrameStatus::kOk: break;
        case engine::SequencedFrameStatus::kCorrupt: res.corrupt += 1; return;  // as a lost packet
        case engine::SequencedFrameStatus::kMalformed: throw std::logic_error("sod: a frame changed its size");  // no fault does
      }
      if (std::int64_t{k} != step_now) {  // no delay on the link: only the current sample is genuine
        res.refused_sequence += 1;
        return;
      }
      if (rx.on_packet(i, k, y) != node::FrameStatus::kOk) {
        res.refused_non_finite += 1;
        return;
      }
      lost_run[i] = 0;
    });
  }
  const engine::HandlerId compute = kernel.add_handler("sod estimator", [&](std::uint64_t kk) {
    const auto k = static_cast<node::SequenceNumber>(kk);
    if (kk > 0 && est.predict(u) == Status::kNonFinite) ++res.estimator_resets;
    node::HeldMeasurement<double> m[kNodes];
    for (std::size_t i = 0; i < kNodes; ++i) {
      m[i] = rx.measurement(i, k);
      const Status st = m[i].present ? est.correct(i, m[i].z, m[i].r_bar) : Status::kOk;
      if (st == Status::kSingular) throw std::runtime_error("sod: innovation variance not positive");
      if (st == Status::kNonFinite) ++res.estimator_resets;
      if (m[i].dropouts > last_d[i]) res.detected[i] += m[i].dropouts - last_d[i];
      last_d[i] = m[i].arrived ? 0 : m[i].dropouts;
    }
    const auto& x = plant.state();
    const auto& xh = est.estimate();
    const auto& p = est.covariance();
    if (kk > 0) {
      const double e0 = x[0] - xh[0], e1 = x[1] - xh[1];
      const double det = p(0, 0) * p(1, 1) - p(0, 1) * p(1, 0);
      res.nees += (p(1, 1) * e0 * e0 - 2 * p(0, 1) * e0 * e1 + p(0, 0) * e1 * e1) / det;
      res.e[0] += e0 * e0;
      res.e[1] += e1 * e1;
      if (static_cast<std::int64_t>(kk) >= tail_from) {
        res.e_tail[0] += e0 * e0;
        res.e_tail[1] += e1 * e1;
        ++tail_count;
      }
    }
    if (trace != nullptr) {
      trace->t_s.push_back(static_cast<double>(kk) * model.period_s());
      for (std::size_t i = 0; i < kNodes; ++i) {
        trace->x[i].push_back(x[i]);
        trace->x_hat[i].push_back(xh[i]);
        trace->p[i].push_back(p(i, i));
        trace->y[i].push_back(y_now[i]);
        trace->z[i].push_back(m[i].present ? m[i].z : std::numeric_limits<double>::quiet_NaN());
        trace->r_bar[i].push_back(m[i].present ? m[i].r_bar : std::numeric_limits<double>::quiet_NaN());
        trace->cause[i].push_back(cause_now[i]);
        trace->arrived[i].push_back(m[i].arrived ? 1 : 0);
        trace->dropouts[i].push_back(m[i].dropouts);
        trace->true_lost_run[i].push_back(lost_run[i]);
      }
    }
  });
  engine::HandlerId sample_handler{};
  sample_handler = kernel.add_handler("sod sample", [&](std::uint64_t kk) {
    const auto k = static_cast<node::SequenceNumber>(kk);
    step_now = static_cast<std::int64_t>(kk);
    const auto& x = plant.state();
    for (std::size_t i = 0; i < kNodes; ++i) {
      double y = 0;
      for (std::size_t j = 0; j < kStates; ++j) y += model.c(i, j) * x[j];
      const double v = meas[i]->normal();  // drawn every sample, sent or not: the stream stays aligned
      if (cfg.noise) y += std::sqrt(model.r_diag[i]) * v;
      y_now[i] = y;
      V1 yv;
      yv[0] = y;
      const node::SendCause cause = rule[i].evaluate(k, yv);
      cause_now[i] = static_cast<std::uint8_t>(cause);
      if (cause == node::SendCause::kNone) continue;
      rule[i].on_sent(k, yv);  // no acknowledgement
      res.sends[i] += 1;
      if (cause == node::SendCause::kTime) res.time_sends[i] += 1;
      if (faulted) {
        std::vector<std::uint8_t> bytes = engine::encode_sequenced_frame(k, &y, 1);
        std::vector<std::vector<std::uint8_t>> extra;
        faults[i]->apply(kernel.now(), bytes, extra);
        const std::optional<engine::SimTime> at = link[i]->transmit(kernel.now());
        if (!at) {
          res.lost[i] += 1;
          ++lost_run[i];
          continue;
        }
        extra.insert(extra.begin(), std::move(bytes));
        for (auto& f : extra) {
          kernel.schedule(*at, engine::EventClass::kDelivery, deliver_frame, (frames.size() << 1) | i);
          frames.push_back(std::move(f));
        }
        continue;
      }
      const std::optional<engine::SimTime> arrival = link[i]->transmit(kernel.now());
      if (!arrival) {
        res.lost[i] += 1;
        ++lost_run[i];
        continue;
      }
      pending_y[i] = y;
      kernel.schedule(*arrival, engine::EventClass::kDelivery, deliver, (kk << 1) | i);
    }
    kernel.schedule(kernel.now(), engine::EventClass::kCompute, compute, kk);
    if (static_cast<std::int64_t>(kk) < cfg.steps) kernel.schedule(kernel.now() + period, engine::EventClass::kSample, sample_handler, kk + 1);
  });
  kernel.schedule(engine::SimTime{0}, engine::EventClass::kSample, sample_handler, 0);
  kernel.run_until(end);
  res.events = static_cast<double>(kernel.events_run());

  for (std::size_t i = 0; i < kNodes; ++i)
    if (faults[i]) res.injected += faults[i]->counters();
  const double n = static_cast<double>(cfg.steps);
  res.nees /= n;
  for (std::size_t i = 0; i < kNodes; ++i) {
    res.e[i] /= n;
    res.e_tail[i] = tail_count > 0 ? res.e_tail[i] / static_cast<double>(tail_count) : 0.0;
  }
  return res;
}

}  // namespace oneshot::sod
