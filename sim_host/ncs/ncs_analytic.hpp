/// @file ncs_analytic.hpp
/// @brief Study ncs, analytic mode (issue 23): the exact expected cost over the process and
///        measurement noise of one run's timing, on the engine's JumpLinearCost.
///
/// The run itself is simulated noise-free (the same seed gives the same delays and τ_c: every
/// source has its own stream); beside it the tracker propagates the mean and covariance of
///     z = [x (2); u held (1); y in flight (2); controller memory (3); command in flight (1); echo (1)]
/// through the same events: a flow between plant events, and at
///  - a sample:   y ← C x + v, v ~ N(0, R);
///  - a compute:  the firmware estimator / law's affine map, probed on copies of the node's
///                object taken just before it ran (the mean inputs, then each input moved by δ:
///                its columns), the command u = u_ref − L (x̂ − x_ref) of SyncControllerNode;
///  - an apply:   u ← command, echo ← u (the value the next request carries).
/// Every mean is checked against the value the simulated nodes produced (y, x̂, u): the largest
/// difference is reported and a run whose difference passes 1e-9 of the signal is refused.
/// Every approach of the study is linear given the timing; a run is refused (with the reason)
/// when a command was clamped, late or filled, an estimator run inexact, two samples in flight,
/// or faults injected.
#pragma once

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <iterator>
#include <memory>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>

#include "ncs_loop.hpp"
#include "ncs_model.hpp"
#include "oneshot/engine/affine_probe.hpp"
#include "oneshot/engine/jump_linear_cost.hpp"
#include "oneshot/engine/sweep.hpp"
#include "oneshot/engine/sweep_statistics.hpp"
#include "oneshot/node/message.hpp"
#include "oneshot/node/sampling_sync_laws.hpp"
#include "oneshot/node/sync_estimators.hpp"
#include "oneshot/standard_kalman.hpp"

namespace oneshot::ncs {

inline constexpr std::size_t kZ = 10;  ///< Size of the closed-loop state z.
/// Offsets in z: plant state, held input, sample in flight, controller memory, command, echo.
enum ZIndex : std::size_t { kZx = 0, kZu = 2, kZy = 3, kZmem = 5, kZcmd = 8, kZecho = 9 };

/// The code of a refusal reason (0: none; the table stores it per run).
int analytic_refusal_code(const std::string& reason);
/// The reason of a refusal code.
const char* analytic_refusal_text(int code);
/// Names of the metrics an analytic sweep adds (`ncs table --analytic`, `study run --analytic`).
inline constexpr const char* kAnalyticMetrics[] = {"analytic", "analytic_refused", "analytic_mismatch"};
/// The values of kAnalyticMetrics for one run: `a` on `sc` with `seed` and `options` in
/// RunOptions::analytic mode — E[J] over the noise (0 when refused), the refusal's code
/// (analytic_refusal_code), the largest mean mismatch.
std::array<double, std::size(kAnalyticMetrics)> analytic_metrics(const Context& ctx, Approach a, const Scenario& sc,
                                                                  std::uint64_t seed, RunOptions options);
/// `ncs analytic-benchmark`: ns per flow and per jump of the engine's propagation on z, and
/// the wall time of an analytic AK run beside the noise-free run (a benchmark, not a test).
nlohmann::json analytic_benchmark(const Context& ctx, std::uint64_t seed);
/// `ncs table --analytic` (and `study run --analytic`): per approach analytic_mean,
/// analytic_ci95 (over the timing draws), the analytic ratio to I ("reference I refused"
/// when I is), the paired MC − analytic, variance_reduction (or analytic_refused with the reason
/// and analytic_refused_runs), the table's variance_reduction (the smallest; and the median,
/// variance_reduction_median), analytic_paired_differences (per seed, as paired_differences;
/// pairs with a refused approach left out), and a markdown table appended to `md`; `mc` is
/// the summary of the Monte Carlo cost.
void analytic_outputs(const engine::SweepResults& results, const engine::SweepSummary& mc, nlohmann::json& j,
                      std::ostringstream& md);

/// x̂ of an estimator copy set to `x` (the half Kalman keeps its P⁻; the predictor has no memory).
template <typename F, typename S, typename D>
void set_estimate(node::HalfKalmanEstimator<F, S, D>& e, const Vector<double, kN>& x, const Vector<double, kM>& u) {
  const auto p = e.filter().covariance();
  e.reset(x, p, u);
}
/// The filterless predictor has no memory.
template <typename F, typename S, typename D>
void set_estimate(node::SampledStatePredictor<F, S, D>&, const Vector<double, kN>&, const Vector<double, kM>&) {}

/// x̂ of a StandardKalman copy set to `x`, P and the first-sample flag kept: through the
/// filter's protected core, on a probe derived from it and sliced back.
template <typename F, typename S>
void set_filter_estimate(StandardKalman<F, S>& f, const Vector<double, kN>& x) {
  struct Probe : StandardKalman<F, S> {
    explicit Probe(const StandardKalman<F, S>& b) : StandardKalman<F, S>(b) {}
    void set(const Vector<double, kN>& v) { this->core_.reset(v, this->core_.covariance()); }
  };
  Probe p(f);
  p.set(x);
  f = p;
}

/// A law's memory in z: S+ [u_{k−1}; 0; 0], static feedback none, the periodic Kalman law
/// [x̂ (2); the input it predicts with]. get_memory reads it, set_memory sets it on a copy.
template <typename R>
Vector<double, 3> get_memory(node::DelayCompensatedLaw<double, kN, kM, R>& law) { return Vector<double, 3>({law.u_prev[0], 0, 0}); }
/// S+: u_{k−1}.
template <typename R>
void set_memory(node::DelayCompensatedLaw<double, kN, kM, R>& law, const Vector<double, 3>& m) { law.u_prev[0] = m[0]; }
/// Static feedback has no memory.
template <typename R>
Vector<double, 3> get_memory(node::StateFeedbackLaw<double, kN, kM, R>&) { return Vector<double, 3>{}; }
/// Static feedback has no memory.
template <typename R>
void set_memory(node::StateFeedbackLaw<double, kN, kM, R>&, const Vector<double, 3>&) {}
/// The periodic Kalman law: x̂ and its applied input.
template <typename F, typename S, typename R>
Vector<double, 3> get_memory(node::PeriodicKalmanLaw<F, S, R>& law, const Vector<double, kM>& u) {
  const auto& x = law.filter().prediction();
  return Vector<double, 3>({x[0], x[1], u[0]});
}
/// The periodic Kalman law: x̂ and its applied input.
template <typename F, typename S, typename R>
void set_memory(node::PeriodicKalmanLaw<F, S, R>& law, const Vector<double, 3>& m) {
  set_filter_estimate(law.filter(), Vector<double, kN>({m[0], m[1]}));
  law.filter().set_applied_input(Vector<double, kM>({m[2]}));
}
/// The memory after a computation that sent u (the laws without a filter ignore u).
template <typename Law>
Vector<double, 3> memory_after(Law& law, const Vector<double, kM>&) { return get_memory(law); }
/// The periodic Kalman law: x̂ and u.
template <typename F, typename S, typename R>
Vector<double, 3> memory_after(node::PeriodicKalmanLaw<F, S, R>& law, const Vector<double, kM>& u) { return get_memory(law, u); }

/// Mean and covariance of z through one run's events, and the expected cost.
class AnalyticTracker {
 public:
  using Jlc = engine::JumpLinearCost<kN, kM, kZ>;  ///< The engine's propagation.
  using Map = Jlc::Map;                             ///< Event map E.
  using Z = Jlc::Z;                                 ///< z.

  /// Plant and cost (Q_c zero when noise-free), C, measurement covariance R (zero when
  /// noise-free), the controller's L; x0 the initial state, mem0 the controller's initial memory.
  AnalyticTracker(const engine::JumpLinearPlant<kN, kM>& plant, const Matrix<double, kP, kN>& c,
                  const Matrix<double, kP, kP>& r, const Matrix<double, kM, kN>& l, const Vector<double, kN>& x0,
                  const Vector<double, kN>& mem0);

  /// Flow to the plant's event at t.
  void flow_to(engine::SimTime t);
  /// The cost's reference from now on.
  void set_reference(const Vector<double, kN>& x_ref, const Vector<double, kM>& u_ref) { jl_.set_reference(x_ref, u_ref); }
  /// A sample y = C x + v taken now; `y_sim` is the simulated (noise-free) sample.
  void sample(engine::SimTime t, const Vector<double, kP>& y_sim);
  /// The plant applies the command in flight; `u_sim` is what the simulated actuator applied.
  void apply(const Vector<double, kM>& u_sim);

  /// A synchronized controller's computation: `before` is a copy of its estimator taken
  /// before it ran, `after` the estimator after, x_ref/u_ref the set-point of period k,
  /// `u_sim` the command it computed; τ = t_k − t_s of the last sample (h the period).
  template <typename Est>
  void compute_sync(const Est& before, const Est& after, std::int64_t h_us, const Vector<double, kN>& x_ref,
                    const Vector<double, kM>& u_ref, const Vector<double, kM>& u_sim) {
    if (!take_sample()) return;
    const std::int64_t ts = last_sample_us_;
    const auto tau = static_cast<std::int32_t>((ts / h_us + 1) * h_us - ts);
    // Inputs w = [x̂⁻ (2); y (2); echo (1)] at their indices in z.
    const std::size_t idx[5] = {kZmem, kZmem + 1, kZy, kZy + 1, kZecho};
    const auto eval = [&](const Vector<double, 5>& w) {
      Est e = before;
      const Vector<double, kM> echo({w[4]});
      set_estimate(e, Vector<double, kN>({w[0], w[1]}), echo);
      (void)e.update(tau, Vector<double, kP>({w[2], w[3]}), echo);
      return Vector<double, kN>(e.estimate());
    };
    Map e = Map::identity();
    Z g{};
    probe<5, kN>(eval, idx, {kZmem, kZmem + 1}, 1.0, e, g);
    check(g[kZmem] + row_dot(e, kZmem), after.estimate()[0]);
    check(g[kZmem + 1] + row_dot(e, kZmem + 1), after.estimate()[1]);
    // u = u_ref − L (x̂ − x_ref), in terms of the old z.
    for (std::size_t j = 0; j < kZ; ++j) e(kZcmd, j) = -(l_(0, 0) * e(kZmem, j) + l_(0, 1) * e(kZmem + 1, j));
    g[kZcmd] = u_ref[0] + l_(0, 0) * x_ref[0] + l_(0, 1) * x_ref[1] - l_(0, 0) * g[kZmem] - l_(0, 1) * g[kZmem + 1];
    jl_.jump(e, g);
    check(jl_.mean()[kZcmd], u_sim[0]);
    cmd_fresh_ = true;
  }

  /// A sampling loop's law computed on the last sample, period `seq`; `before` is a copy of
  /// the law taken before it ran (its memory, S+'s u_{k−1}, is z's first memory entry).
  template <typename Law>
  void compute_law(const Law& before, node::SequenceNumber seq) {
    if (!take_sample()) return;
    const std::size_t idx[5] = {kZy, kZy + 1, kZmem, kZmem + 1, kZmem + 2};
    const auto eval = [&](const Vector<double, 5>& w) {
      Law law = before;
      set_memory(law, Vector<double, 3>({w[2], w[3], w[4]}));
      node::Message<node::VectorPayload<double, kN>> m{};
      m.seq = seq;
      m.payload.value = Vector<double, kN>({w[0], w[1]});
      Vector<double, kM> u{};
      (void)law.compute(m, true, McuInstant{}, u);
      const Vector<double, 3> mem = memory_after(law, u);
      return Vector<double, 4>({u[0], mem[0], mem[1], mem[2]});  // the command and the memory after
    };
    Map e = Map::identity();
    Z g{};
    probe<5, 4>(eval, idx, {kZcmd, kZmem, kZmem + 1, kZmem + 2}, 1e-4, e, g);
    jl_.jump(e, g);
    cmd_fresh_ = true;
  }

  /// Starts again at `t` from mean `m` and covariance `s`, the cost at zero, nothing in flight
  /// (the stationary analysis runs one period at a time: ncs_stationary.hpp).
  void restart(engine::SimTime t, const Z& m, const Jlc::Cov& s) {
    jl_.reset(m, s);
    jl_.clear_cost();
    now_ = t;
    last_sample_us_ = t.count() / 1000;
    y_fresh_ = false;
    cmd_fresh_ = false;
    computed_ = false;
  }
  const Jlc::Cov& covariance() const { return jl_.covariance(); }  ///< Σ = Cov z now.

  /// Refuses the run with `reason` (the first reason is kept).
  void refuse(const std::string& reason) {
    if (refusal_.empty()) refusal_ = reason;
  }
  const std::string& refusal() const { return refusal_; }             ///< "" unless refused.
  /// The expected cost, refusal and mismatch into a run's result.
  void report(RunResult& r) const {
    r.analytic = jl_.cost();
    r.analytic_refusal = refusal_;
    r.analytic_mismatch = mismatch_;
  }
  const engine::ExpectedCost& cost() const { return jl_.cost(); }     ///< Expected cost so far.
  /// The expected cost at `t` (no event since the last one): a copy flowed to t, the run unchanged.
  engine::ExpectedCost cost_at(engine::SimTime t) const {
    Jlc j = jl_;
    j.flow(t - now_);
    return j.cost();
  }
  double mismatch() const { return mismatch_; }                       ///< Largest |mean − simulated| / scale.

 private:
  /// Columns of the affine map out = f(w) at the mean of the inputs (rows `out` of E, g):
  /// engine::probe_affine on the inputs at their indices in z.
  template <std::size_t W, std::size_t O, typename F>
  void probe(const F& f, const std::size_t (&idx)[W], const std::size_t (&out)[O], double delta, Map& e, Z& g) const {
    Vector<double, W> w0;
    for (std::size_t j = 0; j < W; ++j) w0[j] = jl_.mean()[idx[j]];
    Matrix<double, O, W> jac;
    Vector<double, O> b;
    engine::probe_affine<W, O>(f, w0, delta, jac, b);
    for (std::size_t i = 0; i < O; ++i) {
      for (std::size_t j = 0; j < kZ; ++j) e(out[i], j) = 0;
      for (std::size_t j = 0; j < W; ++j) e(out[i], idx[j]) += jac(i, j);
      g[out[i]] = b[i];
    }
  }
  double row_dot(const Map& e, std::size_t row) const {
    double s = 0;
    for (std::size_t j = 0; j < kZ; ++j) s += e(row, j) * jl_.mean()[j];
    return s;
  }
  bool take_sample();
  void check(double mean, double sim);

  Jlc jl_;
  Matrix<double, kP, kN> c_;
  Matrix<double, kP, kP> r_;
  Matrix<double, kM, kN> l_;
  engine::SimTime now_{0};
  std::int64_t last_sample_us_ = 0;
  bool y_fresh_ = false;
  bool cmd_fresh_ = false;
  bool computed_ = false;
  double mismatch_ = 0;
  std::string refusal_;
};

/// The tracker of a run of `a` on `sc` (noise of the approach unless `opt.noise_free`; I has
/// none), started at x0 with x̂ = x0 and the set-point (x0, u_ref0); refused from the start
/// when faults are injected.
std::unique_ptr<AnalyticTracker> make_tracker(const Context& ctx, const Scenario& sc, Approach a, const Design& d,
                                              const RunOptions& opt, const Vector<double, kN>& x0,
                                              const Vector<double, kM>& u_ref0);
/// Refuses an analytic run whose noise-free trajectory left the linear regime: a clamped
/// command (the map is affine only inside the actuator range), a late command, an inexact
/// estimator run.
void refuse_nonlinear_runs(RunResult& r);

}  // namespace oneshot::ncs
