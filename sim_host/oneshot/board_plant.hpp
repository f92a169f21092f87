/// @file board_plant.hpp
/// @brief The reference board as an engine plant: PWM-driven linear circuit, ADC, process
///        noise, and the exact control cost along the trajectory.
///
/// PWM: edge-aligned, common carrier of period T; channel j is high on the first
/// T_h,j = round(code_j·T/steps) ns of every period (duty saturated to 0–100 %), its
/// level v_low or v_high. A new duty acts immediately or from the next period start; the
/// duty in force at power-on is set with initialize_duty(), whatever the register mode.
///
/// Propagation is exact between PWM edges: on a segment of length d with constant
/// levels v, in deviation coordinates e = x − x_ref, ṽ = v − u_ref (A x_ref + B u_ref = 0),
///     e(d) = Φ(d) e + Γ(d) ṽ,   ∫₀ᵈ eᵀQ1c e ds = [e; ṽ]ᵀ G(d) [e; ṽ],
/// with Φ, Γ, G from one Van Loan exponential of [[−Fᵀ, W], [0, F]] d, F = [[A, B], [0, 0]],
/// W = blkdiag(Q1c, 0). A full PWM period is the affine map w ↦ S w on w = [e; 1] with cost
/// wᵀ C w; n periods use S^(2^j) and C_(2^j) = C_j + S_jᵀ C_j S_j (binary powers), so a
/// 50 ms interval costs about ten small products rather than 2000 edges, with the same
/// result (tests/sim_host/oneshot/board_plant_test.cpp checks it edge by edge).
///
/// advance_to() is a physical event: the interval since the last one receives one exact
/// N(0, Q_d(Δ)) draw and its expected noise cost (process_noise.hpp). The input term of
/// the cost uses the commanded input (the duty-cycle average), not the switching waveform.
/// A state trace (record_trace) is filled from a separate stream by bridge draws, so it
/// never changes the run.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "oneshot/assert_handler.hpp"
#include "oneshot/engine/cost.hpp"
#include "oneshot/engine/exact_segment.hpp"
#include "oneshot/engine/process_noise.hpp"
#include "oneshot/engine/sim_time.hpp"
#include "oneshot/engine/trace_sample.hpp"
#include "oneshot/matrix.hpp"
#include "oneshot/engine/random_stream.hpp"

namespace oneshot::engine {

/// When a new PWM duty takes effect.
enum class PwmUpdate : std::uint8_t {
  kImmediate,   ///< At the write (compare register updated at once).
  kNextPeriod,  ///< At the next period start (double-buffered register).
};

/// Board and plant parameters (SI units, times in ns).
template <std::size_t N, std::size_t M, std::size_t P>
struct CircuitConfig {
  Matrix<double, N, N> a;        ///< A (1/s).
  Matrix<double, N, M> b;        ///< B.
  Matrix<double, P, N> c;        ///< C.
  Matrix<double, N, N> qc;       ///< Process noise intensity Q_c (V²/s).
  Matrix<double, N, N> q1c;      ///< Cost weight on the state error.
  Matrix<double, M, M> q2c;      ///< Cost weight on the input error.
  Matrix<double, N, P> nx;       ///< x_ref = N_x r.
  Matrix<double, M, P> nu;       ///< u_ref = N_u r.
  std::int64_t pwm_period_ns = 0;  ///< PWM carrier period.
  std::int32_t duty_steps = 0;   ///< Duty resolution.
  Vector<double, M> v_low;       ///< Input level while low (V).
  Vector<double, M> v_high;      ///< Input level while high (V).
  PwmUpdate update = PwmUpdate::kImmediate;  ///< Duty register behaviour.
  int adc_bits = 12;             ///< ADC resolution.
  Vector<double, P> adc_min;     ///< Voltage at code 0.
  Vector<double, P> adc_lsb;     ///< One code (V).
  bool process_noise = true;     ///< Inject process noise (off for deterministic tests).
};

/// Exact emulation of the PWM-driven circuit.
template <std::size_t N, std::size_t M, std::size_t P>
class BoardPlant {
 public:
  static constexpr std::size_t kStates = N;   ///< n.
  static constexpr std::size_t kInputs = M;   ///< m.
  static constexpr std::size_t kOutputs = P;  ///< p.
  static constexpr std::size_t kK = N + M;
  using State = Vector<double, N>;
  using Aug = Matrix<double, N + 1, N + 1>;
  using Sample = TraceSample<N, M, P>;

  /// Board at t = 0, state 0, duty 0, set-point 0; `noise` feeds the process noise.
  BoardPlant(const CircuitConfig<N, M, P>& config, RandomStream noise)
      : cfg_(config), noise_rng_(std::move(noise)), noise_(config.a, config.qc, config.q1c), segments_(config.a, config.b, config.q1c) {
    ONESHOT_ASSERT(cfg_.pwm_period_ns > 0 && cfg_.duty_steps > 0);
    set_setpoint(Vector<double, P>{});
  }

  /// Current time.
  SimTime now() const { return now_; }
  /// Current state x (absolute).
  const State& state() const { return x_; }
  /// Sets the state (tests).
  void set_state(const State& x) { x_ = x; }
  /// Cost accumulated so far.
  const CostBreakdown& cost() const { return cost_; }
  /// Duty code in effect on channel j.
  std::int32_t duty(std::size_t j) const { return codes_[j]; }
  /// Commanded input of channel j: the duty-cycle average (V).
  double commanded_input(std::size_t j) const { return level_average(j, codes_[j]); }
  /// Current set-point.
  const Vector<double, P>& setpoint() const { return r_; }
  /// Recorded trace (record_trace).
  const std::vector<Sample>& trace() const { return trace_; }

  /// The duty in force now on channel j, whatever the register mode (power-on state).
  void initialize_duty(std::size_t j, std::int32_t code) {
    codes_[j] = std::clamp(code, 0, cfg_.duty_steps);
    invalidate();
  }

  /// Writes the duty register of channel j at the current time (saturated to [0, steps]).
  void set_duty(std::size_t j, std::int32_t code) {
    code = std::clamp(code, 0, cfg_.duty_steps);
    if (cfg_.update == PwmUpdate::kImmediate) {
      if (codes_[j] != code) {
        codes_[j] = code;
        invalidate();
      }
      return;
    }
    if (!pending_) {
      for (std::size_t i = 0; i < M; ++i) pending_codes_[i] = codes_[i];
    }
    pending_codes_[j] = code;
    pending_ = true;
    pending_at_ = Duration{(now_.count() / cfg_.pwm_period_ns + 1) * cfg_.pwm_period_ns};
  }

  /// Changes the set-point at the current time.
  void set_setpoint(const Vector<double, P>& r) {
    r_ = r;
    x_ref_ = cfg_.nx * r;
    u_ref_ = cfg_.nu * r;
    invalidate();
  }

  /// Records the true state every `step` from now on; bridge draws come from `rng`.
  void record_trace(Duration step, RandomStream rng) {
    ONESHOT_ASSERT(step.count() > 0);
    trace_step_ = step;
    trace_rng_ = std::move(rng);
    trace_.push_back(Sample{now_, x_, r_, inputs(codes_)});
    trace_next_ = now_ + step;
  }

  /// Advances to t1 ≥ now: exact propagation, cost, then the interval's process noise.
  void advance_to(SimTime t1) {
    ONESHOT_ASSERT(t1 >= now_);
    const SimTime start = now_;
    const std::size_t first_new = trace_.size();
    if (trace_step_.count() > 0) trace_deterministic(t1);
    State e = x_ - x_ref_;
    SimTime t = now_;
    while (t < t1) {
      SimTime stop = t1;
      if (pending_ && pending_at_ > t && pending_at_ < stop) stop = pending_at_;
      propagate(e, t.count(), stop.count(), true);
      double u_cost = 0;
      Vector<double, M> dv;
      for (std::size_t j = 0; j < M; ++j) dv[j] = level_average(j, codes_[j]) - u_ref_[j];
      for (std::size_t i = 0; i < M; ++i)
        for (std::size_t k = 0; k < M; ++k) u_cost += dv[i] * cfg_.q2c(i, k) * dv[k];
      cost_.input += u_cost * seconds((stop - t).count());
      t = stop;
      if (pending_ && t >= pending_at_) {
        for (std::size_t j = 0; j < M; ++j) codes_[j] = pending_codes_[j];
        pending_ = false;
        invalidate();
      }
    }
    x_ = e + x_ref_;
    now_ = t1;
    State n_end{};
    if (cfg_.process_noise && t1 > start) {
      n_end = noise_.draw(t1 - start, noise_rng_);
      x_ = x_ + n_end;
      cost_.noise += noise_.interval_cost(t1 - start);
    }
    if (trace_.size() > first_new) trace_noise(start, first_new, n_end);
  }

  /// ADC code of output o for the current state plus `noise_volts` (saturating).
  std::int32_t adc_code(std::size_t o, double noise_volts) const {
    double v = noise_volts;
    for (std::size_t i = 0; i < N; ++i) v += cfg_.c(o, i) * x_[i];
    const double code = std::floor((v - cfg_.adc_min[o]) / cfg_.adc_lsb[o]);
    const double top = std::ldexp(1.0, cfg_.adc_bits) - 1;
    return static_cast<std::int32_t>(std::clamp(code, 0.0, top));
  }

  /// Q_d(Δ) of the process noise (Van Loan).
  Matrix<double, N, N> process_covariance(Duration delta) const { return noise_.covariance(delta); }
  /// E ∫₀^Δ nᵀ Q1c n ds for the noise path n started at 0.
  double expected_noise_cost(Duration delta) const { return noise_.expected_cost(delta); }

 private:
  using Segment = ExactSegment<N, M>;

  static double seconds(std::int64_t ns) { return static_cast<double>(ns) * 1e-9; }

  double level_average(std::size_t j, std::int32_t code) const {
    return cfg_.v_low[j] + (cfg_.v_high[j] - cfg_.v_low[j]) * code / cfg_.duty_steps;
  }
  Vector<double, M> inputs(const std::int32_t (&codes)[M]) const {
    Vector<double, M> u;
    for (std::size_t j = 0; j < M; ++j) u[j] = level_average(j, codes[j]);
    return u;
  }

  std::int64_t high_ns(std::size_t j) const {
    return (static_cast<std::int64_t>(codes_[j]) * cfg_.pwm_period_ns + cfg_.duty_steps / 2) / cfg_.duty_steps;
  }

  void invalidate() { powers_ = 0; }

  Vector<double, M> levels_at_phase(std::int64_t phase_ns) const {
    Vector<double, M> v;
    for (std::size_t j = 0; j < M; ++j) v[j] = (phase_ns < high_ns(j) ? cfg_.v_high[j] : cfg_.v_low[j]) - u_ref_[j];
    return v;
  }

  /// Calls f(duration, ṽ) for each constant-level segment of [ta, tb] within one period
  /// starting at base.
  template <typename F>
  void for_each_segment(std::int64_t base, std::int64_t ta, std::int64_t tb, F&& f) const {
    std::int64_t cuts[M];
    for (std::size_t j = 0; j < M; ++j) cuts[j] = base + high_ns(j);
    std::sort(cuts, cuts + M);
    std::int64_t t = ta;
    for (std::size_t j = 0; j <= M && t < tb; ++j) {
      const std::int64_t next = j < M ? std::min(std::max(cuts[j], t), tb) : tb;
      if (next > t) {
        f(next - t, levels_at_phase(t - base));
        t = next;
      }
    }
  }

  void apply_segment(State& e, std::int64_t d, const Vector<double, M>& dv, bool cost) {
    const Segment& s = segments_.get(d);
    if (cost) {
      Vector<double, kK> z;
      z.template set_block<0, 0>(e);
      z.template set_block<N, 0>(dv);
      cost_.state += quadratic_form(s.g, z);
    }
    e = s.phi * e + s.gamma * dv;
  }

  /// e over [t0, t1] with the duties in force; the state cost is added when `cost`.
  void propagate(State& e, std::int64_t t0, std::int64_t t1, bool cost) {
    const std::int64_t period = cfg_.pwm_period_ns;
    const std::int64_t base0 = (t0 / period) * period;
    const std::int64_t boundary = base0 + period;
    const auto apply = [&](std::int64_t d, const Vector<double, M>& dv) { apply_segment(e, d, dv, cost); };
    if (t1 <= boundary) {
      for_each_segment(base0, t0, t1, apply);
      return;
    }
    for_each_segment(base0, t0, boundary, apply);
    const std::int64_t n = (t1 - boundary) / period;
    if (n > 0) full_periods(e, n, cost);
    const std::int64_t tail = boundary + n * period;
    for_each_segment(tail, tail, t1, apply);
  }

  /// The per-period map S and cost C on w = [e; 1] for the current duties and set-point.
  void build_period() {
    Aug s = Aug::identity();
    Aug c;
    for_each_segment(0, 0, cfg_.pwm_period_ns, [&](std::int64_t d, const Vector<double, M>& dv) {
      const Segment& seg = segments_.get(d);
      // z = T w with T = [[I, 0], [0, ṽ]]; segment map [[Φ, Γṽ], [0, 1]].
      Matrix<double, kK, N + 1> tm;
      for (std::size_t i = 0; i < N; ++i) tm(i, i) = 1;
      for (std::size_t j = 0; j < M; ++j) tm(N + j, N) = dv[j];
      const Matrix<double, kK, N + 1> ts = tm * s;
      c = c + ts.transposed() * seg.g * ts;
      Aug step = Aug::identity();
      step.template set_block<0, 0>(seg.phi);
      step.template set_block<0, N>(Matrix<double, N, 1>(seg.gamma * dv));
      s = step * s;
    });
    mirror_upper(c);
    s_pow_[0] = s;
    c_pow_[0] = c;
    powers_ = 1;
  }

  void full_periods(State& e, std::int64_t n, bool cost) {
    if (powers_ == 0) build_period();
    Vector<double, N + 1> w;
    w.template set_block<0, 0>(e);
    w[N] = 1;
    for (std::size_t j = 0; n > 0; ++j, n >>= 1) {
      ONESHOT_ASSERT(j < kMaxPowers);
      while (powers_ <= j) {
        const Aug& sp = s_pow_[powers_ - 1];
        const Aug& cp = c_pow_[powers_ - 1];
        c_pow_[powers_] = cp + sp.transposed() * cp * sp;
        mirror_upper(c_pow_[powers_]);
        s_pow_[powers_] = sp * sp;
        ++powers_;
      }
      if ((n & 1) != 0) {
        if (cost) cost_.state += quadratic_form(c_pow_[j], w);
        w = s_pow_[j] * w;
      }
    }
    e = w.template block<0, 0, N, 1>();
  }

  /// Appends the trace points in (now, t1] with their noise-free states (no cost, no draw).
  void trace_deterministic(SimTime t1) {
    State e = x_ - x_ref_;
    SimTime t = now_;
    bool switched = false;
    while (trace_next_ <= t1) {
      const SimTime s = trace_next_;
      if (pending_ && !switched && pending_at_ > t && pending_at_ < s) {
        propagate(e, t.count(), pending_at_.count(), false);
        t = pending_at_;
        switched = true;
        swap_pending();
      }
      propagate(e, t.count(), s.count(), false);
      t = s;
      trace_.push_back(Sample{s, e + x_ref_, r_, inputs(switched ? pending_codes_ : codes_)});
      trace_next_ = s + trace_step_;
    }
    if (switched) swap_pending();
  }
  /// Exchanges the duties in force with the pending ones (trace walks only).
  void swap_pending() {
    for (std::size_t j = 0; j < M; ++j) std::swap(codes_[j], pending_codes_[j]);
    invalidate();
  }

  /// Adds the bridged noise path to the trace points from index `first` (interval from `start`).
  void trace_noise(SimTime start, std::size_t first, const State& n_end) {
    if (cfg_.process_noise) bridge_trace_noise(trace_, first, start, now_, n_end, noise_, trace_rng_);
  }

  static constexpr std::size_t kMaxPowers = 48;

  CircuitConfig<N, M, P> cfg_;
  RandomStream noise_rng_;
  ProcessNoise<N> noise_;
  SimTime now_{0};
  State x_{};
  Vector<double, P> r_{};
  State x_ref_{};
  Vector<double, M> u_ref_{};
  std::int32_t codes_[M] = {};
  std::int32_t pending_codes_[M] = {};
  bool pending_ = false;
  SimTime pending_at_{0};
  CostBreakdown cost_{};
  ExactSegmentCache<N, M> segments_;
  Aug s_pow_[kMaxPowers];
  Aug c_pow_[kMaxPowers];
  std::size_t powers_ = 0;
  Duration trace_step_{0};
  SimTime trace_next_{0};
  RandomStream trace_rng_{0, "trace"};
  std::vector<Sample> trace_;
};

}  // namespace oneshot::engine
