/// @file closed_loop.cpp
/// @brief One closed-loop run of the dropping study on the engine (see closed_loop.hpp).
#include "closed_loop.hpp"

#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>

#include "oneshot/engine/discrete_plant.hpp"
#include "oneshot/engine/json_fields.hpp"
#include "oneshot/engine/kernel.hpp"
#include "oneshot/engine/link.hpp"
#include "oneshot/engine/psd_math.hpp"
#include "oneshot/engine/sequenced_frame.hpp"
#include "oneshot/finite.hpp"
#include "oneshot/node/buffered_kalman.hpp"
#include "oneshot/number_format.hpp"
#include "oneshot/plant_structure.hpp"
#include "unaware_kalman.hpp"

namespace oneshot::dropping {
namespace {

using Fmt = UniformFormat<double>;
using Structure = DenseStructure<kN, kM, kP>;
using StateVec = Vector<double, kN>;
using InputVec = Vector<double, kM>;
using OutputVec = Vector<double, kP>;
using Cov = Matrix<double, kN, kN>;

node::BufferedKalmanModel<Fmt, kN, kM, kP> filter_model(const DroppingPlant& p, const Matrix<double, kP, kP>& r) {
  node::BufferedKalmanModel<Fmt, kN, kM, kP> m;
  m.step.phi = p.phi;
  m.step.gamma = p.gamma;
  m.q = p.q;
  m.c = p.c;
  m.r = r;
  return m;
}

double trace_of(const Cov& p) { return p(0, 0) + p(1, 1) + p(2, 2); }
double sq_err(const StateVec& a, const StateVec& b) {
  double s = 0;
  for (std::size_t i = 0; i < kN; ++i) s += (a[i] - b[i]) * (a[i] - b[i]);
  return s;
}

engine::LinkConfig sensor_link(double mean_delay_periods, double loss, engine::Duration period) {
  engine::LinkConfig lc;
  lc.name = "sensor";
  lc.delay.kind = engine::DelayModel::Kind::kPoissonPeriods;
  lc.delay.mean_periods = mean_delay_periods;
  lc.delay.period = period;
  lc.delay.shift = period / 2;
  lc.loss.kind = loss > 0 ? engine::LossModel::Kind::kBernoulli : engine::LossModel::Kind::kNone;
  lc.loss.p = loss;
  lc.fifo = false;
  return lc;
}

template <std::size_t kHold>
RunMetrics run_impl(const DroppingPlant& plant, const RunConfig& cfg, std::uint64_t seed) {
  using Filter = node::BufferedKalman<Fmt, Structure, kHold>;
  const engine::Duration period{static_cast<std::int64_t>(plant.plant.period_us) * 1000};
  const std::size_t steps = cfg.steps;
  const engine::SimTime end = period * static_cast<std::int64_t>(steps);
  engine::Kernel kernel(seed);

  engine::DiscretePlantConfig<kN, kM, kP, 1> pc;
  pc.phi = plant.phi;
  pc.gamma = plant.gamma;
  pc.c = plant.c;
  pc.q = plant.q;
  pc.q1 = plant.q1;
  pc.q2 = plant.q2;
  pc.period = period;
  engine::DiscretePlant<kN, kM, kP, 1> sys(pc, kernel.stream("process"));
  {  // x₀ ~ N(0, P₀)
    engine::RandomStream init = kernel.stream("initial");
    const Cov chol = engine::psd_cholesky(plant.p0);
    StateVec w;
    for (std::size_t i = 0; i < kN; ++i) w[i] = init.normal();
    sys.set_state(chol * w);
  }
  engine::attach_discrete_plant(kernel, sys, end);

  const auto model = filter_model(plant, plant.r);
  Matrix<double, kP, kP> r_unaware;
  r_unaware(0, 0) = cfg.unaware_r;
  const auto model_unaware = filter_model(plant, r_unaware);
  Filter filter(model, StateVec{}, plant.p0);
  UnawareKalman unaware(model_unaware, plant.p0);
  // Shadows: the delay-unaware KF (R = 0.05 and 2.5) fed the same packets and inputs while the
  // buffered filter closes the loop: an estimation-only comparison on the same trajectory.
  Matrix<double, kP, kP> r_small, r_nominal;
  r_small(0, 0) = 0.05;
  r_nominal(0, 0) = 2.5;
  const auto model_small = filter_model(plant, r_small), model_nominal = filter_model(plant, r_nominal);
  UnawareKalman shadow_small(model_small, plant.p0), shadow_nominal(model_nominal, plant.p0);
  double sum_shadow_small = 0, sum_shadow_nominal = 0;
  const bool buffered = cfg.estimator == EstimatorKind::kBuffered;

  engine::LinkConfig link_config = cfg.link ? *cfg.link : sensor_link(cfg.mean_delay_periods, cfg.loss, period);
  link_config.name = "sensor";  // the study's link: its streams whatever a study file calls it
  engine::Link link(link_config, seed);
  std::size_t channel_lost = 0;  // Bernoulli channel: γ_k = 0 (clean runs)
  engine::RandomStream meas = kernel.stream("measurement");
  engine::RandomStream gamma_rng = kernel.stream("gamma");
  const double sd_v = std::sqrt(plant.r(0, 0));
  std::vector<double> ys(steps, 0.0);
  std::vector<StateVec> xs(steps);
  std::optional<std::uint32_t> newest;  // newest stamp arrived this period (unaware KF)
  double newest_y = 0;                  // its value
  // Frame faults (faulted runs only: the clean run draws and registers nothing more).
  const bool faulted = !cfg.faults.empty();
  std::optional<engine::LinkFaults> faults;
  if (faulted) faults.emplace(cfg.faults, "sensor", engine::kSequencedFrameLayout, seed);
  std::vector<std::vector<std::uint8_t>> frames;  // delivered by "deliver frame" (arg: index)

  RunMetrics out;
  double sum_tr = 0, sum_err = 0, sum_tr_a = 0, sum_err_a = 0, sum_corr = 0, sum_gamma = 0;
  std::size_t anchors = 0;
  const std::int64_t half_wave = std::llround(cfg.square_wave_period_s * 0.5e9 / static_cast<double>(period.count()));
  if (cfg.trace) {
    out.trace.y.reserve(steps);
  }

  const engine::HandlerId deliver = kernel.add_handler("deliver", [&](std::uint64_t j) {
    OutputVec y;
    y[0] = ys[j];
    if (buffered) {
      const node::ArrivalVerdict v = filter.receive(static_cast<std::uint32_t>(j), y);
      if (v == node::ArrivalVerdict::kOverDelayed) out.over_delayed += 1;
      if (v == node::ArrivalVerdict::kDuplicate) out.duplicates += 1;
    }
    if (!newest || j > *newest) {
      newest = static_cast<std::uint32_t>(j);
      newest_y = ys[j];
    } else {
      out.stale += 1;
    }
  });
  // The controller's frame checks: CRC-16 (corrupt), y finite, stamp not after the period it arrives in (a
  // genuine sample arrives at least half a period after it was taken), then the buffer's
  // window (over-delayed, duplicate) or, for the unaware KF, newer than the period's newest.
  engine::HandlerId deliver_frame{};
  if (faulted) {
    deliver_frame = kernel.add_handler("deliver frame", [&](std::uint64_t i) {
      std::uint32_t j = 0;
      double yj = 0;
      switch (engine::decode_sequenced_frame(frames[i], j, &yj, 1)) {
        case engine::SequencedFrameStatus::kOk: break;
        case engine::SequencedFrameStatus::kCorrupt: out.corrupt += 1; return;  // a lost sample (γ = 0)
        case engine::SequencedFrameStatus::kMalformed: throw std::logic_error("dropping: a frame changed its size");  // no fault does
      }
      if (!std::isfinite(yj)) {
        out.refused_non_finite += 1;
        return;
      }
      const auto period_now = static_cast<std::uint32_t>(kernel.now().count() / period.count());
      if (static_cast<std::int32_t>(period_now - j) < 0) {
        out.refused_sequence += 1;
        return;
      }
      OutputVec y;
      y[0] = yj;
      if (buffered) {
        const node::ArrivalVerdict v = filter.receive(j, y);
        if (v == node::ArrivalVerdict::kOverDelayed) out.over_delayed += 1;
        if (v == node::ArrivalVerdict::kDuplicate) out.duplicates += 1;
      }
      if (!newest || static_cast<std::int32_t>(j - *newest) > 0) {
        newest = j;
        newest_y = yj;
      } else {
        out.stale += 1;
      }
    });
  }
  const engine::HandlerId sample = kernel.add_handler("sample", [&](std::uint64_t k) {
    xs[k] = sys.state();
    const double cx = (plant.c * sys.state())[0];
    ys[k] = cx + sd_v * meas.normal();
    const engine::SimTime now = kernel.now();
    if (faulted) {
      std::vector<std::uint8_t> bytes = engine::encode_sequenced_frame(static_cast<std::uint32_t>(k), &ys[k], 1);
      std::vector<std::vector<std::uint8_t>> extra;
      faults->apply(now, bytes, extra);  // before the channel's draws: they never move
      std::optional<engine::SimTime> at;
      if (cfg.channel == ChannelKind::kNetwork) {
        at = link.transmit(now);
      } else if (gamma_rng.bernoulli(cfg.bernoulli_lambda)) {
        at = now + period / 2;
      } else {
        ++channel_lost;
      }
      if (at) {
        extra.insert(extra.begin(), std::move(bytes));
        for (auto& f : extra) {  // copies travel with the frame, right after it
          kernel.schedule(*at, engine::EventClass::kDelivery, deliver_frame, frames.size());
          frames.push_back(std::move(f));
        }
      }
    } else if (cfg.channel == ChannelKind::kNetwork) {
      if (const auto at = link.transmit(now)) kernel.schedule(*at, engine::EventClass::kDelivery, deliver, k);
    } else if (gamma_rng.bernoulli(cfg.bernoulli_lambda)) {
      kernel.schedule(now + period / 2, engine::EventClass::kDelivery, deliver, k);
    } else {
      ++channel_lost;
    }
    if (cfg.trace) {
      out.trace.y.push_back(ys[k]);
      out.trace.cx.push_back(cx);
    }
  });
  const engine::HandlerId compute = kernel.add_handler("compute", [&](std::uint64_t k) {
    StateVec xhat;
    Cov p;
    Status st;
    std::uint32_t corr;
    std::optional<OutputVec> y_newest;
    if (newest) {
      OutputVec v;
      v[0] = newest_y;
      y_newest = v;
    }
    newest.reset();
    if (buffered) {
      static_cast<void>(shadow_small.step(y_newest));
      static_cast<void>(shadow_nominal.step(y_newest));
      sum_shadow_small += sq_err(sys.state(), shadow_small.estimate());
      sum_shadow_nominal += sq_err(sys.state(), shadow_nominal.estimate());
      st = filter.step();
      xhat = filter.estimate();
      p = filter.covariance();
      corr = filter.last_corrections();
      if (filter.anchor_started() && k >= kHold) {
        ++anchors;
        sum_gamma += filter.last_gamma() ? 1.0 : 0.0;
        sum_tr_a += trace_of(filter.anchor_covariance());
        sum_err_a += sq_err(xs[filter.anchor_index()], filter.anchor());
      }
    } else {
      st = unaware.step(y_newest);
      xhat = unaware.estimate();
      p = unaware.covariance();
      corr = unaware.last_corrections();
    }
    if (st != Status::kOk) out.failed = true;
    if (faulted && !all_finite(xhat)) out.estimate_non_finite += 1;
    const double r_k = ((static_cast<std::int64_t>(k) / half_wave) % 2 == 0) ? cfg.square_wave_amplitude : -cfg.square_wave_amplitude;
    InputVec u = -(plant.l * xhat);
    u[0] += r_k;
    sys.set_input(u);
    if (buffered) {
      filter.set_applied_input(u);
      shadow_small.set_applied_input(u);
      shadow_nominal.set_applied_input(u);
    } else {
      unaware.set_applied_input(u);
    }
    const double tr = trace_of(p), e = sq_err(sys.state(), xhat);
    sum_tr += tr;
    sum_err += e;
    sum_corr += corr;
    if (cfg.trace) {
      out.trace.cxhat.push_back((plant.c * xhat)[0]);
      out.trace.trace_p.push_back(tr);
      out.trace.err.push_back(e);
      out.trace.u.push_back(u[0]);
      out.trace.r.push_back(r_k);
    }
  });
  for (std::size_t k = 0; k < steps; ++k) {
    const engine::SimTime t = period * static_cast<std::int64_t>(k);
    kernel.schedule(t, engine::EventClass::kSample, sample, k);
    kernel.schedule(t, engine::EventClass::kCompute, compute, k);
  }
  kernel.run_until(end);
  out.events = static_cast<double>(kernel.events_run());
  const double n = static_cast<double>(steps);
  out.trace_p = sum_tr / n;
  out.err = sum_err / n;
  out.corrections = sum_corr / n;
  out.cost = sys.cost().total() / n;
  out.reordered = static_cast<double>(link.statistics().reordered);
  const bool network = cfg.channel == ChannelKind::kNetwork;
  out.sent = network ? static_cast<double>(link.statistics().sent) : n;
  out.lost = network ? static_cast<double>(link.statistics().lost) : static_cast<double>(channel_lost);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  out.trace_p_anchor = buffered && anchors > 0 ? sum_tr_a / static_cast<double>(anchors) : nan;
  out.err_anchor = buffered && anchors > 0 ? sum_err_a / static_cast<double>(anchors) : nan;
  out.err_shadow_small_r = buffered ? sum_shadow_small / n : nan;
  out.err_shadow_nominal_r = buffered ? sum_shadow_nominal / n : nan;
  out.gamma = buffered && anchors > 0 ? sum_gamma / static_cast<double>(anchors) : nan;
  if (faults) out.injected = faults->counters();
  return out;
}

template <std::size_t kHold>
double gamma_impl(double mean_delay_periods, double loss, std::size_t steps, std::uint64_t seed) {
  const engine::Duration period{10'000'000};  // any period: delays are whole periods + T/2
  engine::Kernel kernel(seed);
  engine::Link link(sensor_link(mean_delay_periods, loss, period), seed);
  node::ThresholdBuffer<double, kHold> buffer;
  std::size_t taken = 0, judged = 0;
  const engine::HandlerId deliver = kernel.add_handler("deliver", [&](std::uint64_t j) {
    static_cast<void>(buffer.receive(static_cast<std::uint32_t>(j), 0.0));
  });
  const engine::HandlerId sample = kernel.add_handler("sample", [&](std::uint64_t k) {
    if (const auto at = link.transmit(kernel.now())) kernel.schedule(*at, engine::EventClass::kDelivery, deliver, k);
  });
  const engine::HandlerId compute = kernel.add_handler("compute", [&](std::uint64_t k) {
    double y = 0;
    const bool consume = k >= kHold;
    const bool g = buffer.advance(consume, y);
    if (consume) {
      ++judged;
      if (g) ++taken;
    }
  });
  for (std::size_t k = 0; k < steps; ++k) {
    const engine::SimTime t = period * static_cast<std::int64_t>(k);
    kernel.schedule(t, engine::EventClass::kSample, sample, k);
    kernel.schedule(t, engine::EventClass::kCompute, compute, k);
  }
  kernel.run_until(period * static_cast<std::int64_t>(steps));
  return judged == 0 ? std::numeric_limits<double>::quiet_NaN() : static_cast<double>(taken) / static_cast<double>(judged);
}

}  // namespace

void check_dropping_faults(const engine::FaultSpec& spec) {
  for (std::size_t i = 0; i < spec.clauses.size(); ++i) {
    const engine::FaultClause& c = spec.clauses[i];
    if (c.kind == engine::FaultClause::Kind::kRestart)
      throw engine::InputError("fault clause " + std::to_string(i + 1) + " (restart): node '" + c.node +
                               "' cannot restart in study dropping (no restartable node: the sensor stamps its samples "
                               "with the synchronized step index, and the buffered filter's step count, its sequence "
                               "reference, cannot be re-based)");
  }
  engine::check_fault_targets(spec, dropping_link_names(), {});
}

RunMetrics run_closed_loop(const DroppingPlant& plant, const RunConfig& cfg, std::uint64_t seed) {
  check_dropping_faults(cfg.faults);
  if (cfg.steps < 2) throw std::invalid_argument("a run needs at least 2 steps");
  if (!(cfg.square_wave_period_s > 0)) throw std::invalid_argument("square-wave period must be positive");
  if (std::llround(cfg.square_wave_period_s * 0.5e9 / (static_cast<double>(plant.plant.period_us) * 1e3)) < 1)
    throw std::invalid_argument("square-wave period must be at least two steps");
  switch (cfg.t_hold) {
    case 1: return run_impl<1>(plant, cfg, seed);
    case 2: return run_impl<2>(plant, cfg, seed);
    case 3: return run_impl<3>(plant, cfg, seed);
    case 4: return run_impl<4>(plant, cfg, seed);
    case 5: return run_impl<5>(plant, cfg, seed);
    case 6: return run_impl<6>(plant, cfg, seed);
    case 7: return run_impl<7>(plant, cfg, seed);
    case 8: return run_impl<8>(plant, cfg, seed);
    default: throw std::invalid_argument("T_hold must be 1 ... 8 (got " + std::to_string(cfg.t_hold) + ")");
  }
}

double simulate_gamma_frequency(int t_hold, double mean_delay_periods, double loss, std::size_t steps,
                                std::uint64_t seed) {
  switch (t_hold) {
    case 1: return gamma_impl<1>(mean_delay_periods, loss, steps, seed);
    case 2: return gamma_impl<2>(mean_delay_periods, loss, steps, seed);
    case 3: return gamma_impl<3>(mean_delay_periods, loss, steps, seed);
    case 4: return gamma_impl<4>(mean_delay_periods, loss, steps, seed);
    case 5: return gamma_impl<5>(mean_delay_periods, loss, steps, seed);
    case 6: return gamma_impl<6>(mean_delay_periods, loss, steps, seed);
    case 7: return gamma_impl<7>(mean_delay_periods, loss, steps, seed);
    case 8: return gamma_impl<8>(mean_delay_periods, loss, steps, seed);
    default: throw std::invalid_argument("T_hold must be 1 ... 8 (got " + std::to_string(t_hold) + ")");
  }
}

}  // namespace oneshot::dropping
