/// @file board_emulator.hpp
/// @brief The emulated reference board: PWM-driven linear circuit, ADC, process noise,
///        and the exact control cost along the trajectory.
///
/// PWM: edge-aligned, common carrier of period T; channel j is high on the first
/// T_h,j = round(code_j·T/steps) ns of every period (duty saturated to 0–100 %), its
/// level v_low or v_high. A new duty acts immediately or from the next period start.
///
/// Propagation is exact between PWM edges: on a segment of length d with constant
/// levels v, in deviation coordinates e = x − x_ref, ṽ = v − u_ref (A x_ref + B u_ref = 0),
///     e(d) = Φ(d) e + Γ(d) ṽ,   ∫₀ᵈ eᵀQ1c e ds = [e; ṽ]ᵀ G(d) [e; ṽ],
/// with Φ, Γ, G from one Van Loan exponential of [[−Fᵀ, W], [0, F]] d, F = [[A, B], [0, 0]],
/// W = blkdiag(Q1c, 0). A full PWM period is the affine map w ↦ S w on w = [e; 1] with cost
/// wᵀ C w; n periods use S^(2^j) and C_(2^j) = C_j + S_jᵀ C_j S_j (binary powers), so a
/// 50 ms interval costs about ten small products rather than 2000 edges, with the same
/// result (tests/sim_host/board_emulator_test.cpp checks it edge by edge).
///
/// Process noise is continuous white noise of intensity Q_c: at the end of each advance
/// over Δ the state receives an exact N(0, Q_d(Δ)) draw, and the cost receives the exact
/// expected contribution of the noise path inside the interval,
///     E ∫₀^Δ nᵀ Q1c n ds = Σ_{k≥1} tr(Q1c M_k) Δ^{k+1}/(k+1)!,  M₁ = Q_c, M_{k+1} = A M_k + M_k Aᵀ.
/// The input term of the cost uses the commanded input (the duty-cycle average
/// u_min + code·(u_max − u_min)/steps), not the switching waveform.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <unordered_map>

#include "oneshot/assert_handler.hpp"
#include "oneshot/matrix.hpp"
#include "oneshot/matrix_exponential.hpp"
#include "oneshot/sim/random_stream.hpp"

namespace oneshot::sim {

/// When a new PWM duty takes effect.
enum class PwmUpdate : std::uint8_t {
  kImmediate,   ///< At the write (compare register updated at once).
  kNextPeriod,  ///< At the next period start (double-buffered register).
};

/// Board and plant parameters of the emulator (SI units, times in ns).
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

/// Cost accumulated along the trajectory.
struct CostBreakdown {
  double state = 0;  ///< ∫ eᵀ Q1c e dt along the deterministic switching trajectory.
  double noise = 0;  ///< Expected contribution of the noise path inside intervals.
  double input = 0;  ///< ∫ ṽᵀ Q2c ṽ dt of the commanded input.
  /// The total cost J.
  double total() const { return state + noise + input; }
};

/// Exact emulation of the PWM-driven circuit.
template <std::size_t N, std::size_t M, std::size_t P>
class BoardEmulator {
 public:
  static constexpr std::size_t kK = N + M;
  using State = Vector<double, N>;
  using Aug = Matrix<double, N + 1, N + 1>;

  /// Emulator at t = 0, state 0, duty 0, set-point 0; `noise` feeds the process noise.
  BoardEmulator(const CircuitConfig<N, M, P>& config, RandomStream noise)
      : cfg_(config), noise_(std::move(noise)) {
    ONESHOT_ASSERT(cfg_.pwm_period_ns > 0 && cfg_.duty_steps > 0);
    for (std::size_t j = 0; j < M; ++j) codes_[j] = 0;
    // Series coefficients of the expected in-interval noise cost.
    Matrix<double, N, N> mk = cfg_.qc;
    for (std::size_t k = 0; k < kNoiseTerms; ++k) {
      double tr = 0;
      const Matrix<double, N, N> prod = cfg_.q1c * mk;
      for (std::size_t i = 0; i < N; ++i) tr += prod(i, i);
      noise_coeff_[k] = tr;  // tr(Q1c M_{k+1})
      mk = cfg_.a * mk + mk * cfg_.a.transposed();
    }
    for (std::size_t j = 0; j < N; ++j) {
      double col = 0;
      for (std::size_t i = 0; i < N; ++i) col += std::fabs(cfg_.a(i, j));
      a_norm_ = std::max(a_norm_, col);
    }
    set_setpoint(Vector<double, P>{});
  }

  /// Current time (ns).
  std::int64_t now_ns() const { return now_ns_; }
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
    pending_at_ns_ = (now_ns_ / cfg_.pwm_period_ns + 1) * cfg_.pwm_period_ns;
  }

  /// Changes the set-point at the current time.
  void set_setpoint(const Vector<double, P>& r) {
    r_ = r;
    x_ref_ = cfg_.nx * r;
    u_ref_ = cfg_.nu * r;
    invalidate();
  }

  /// Advances to t1 ≥ now: exact propagation, cost, then the interval's process noise.
  void advance_to(std::int64_t t1) {
    ONESHOT_ASSERT(t1 >= now_ns_);
    const std::int64_t start = now_ns_;
    State e = x_ - x_ref_;
    std::int64_t t = now_ns_;
    while (t < t1) {
      std::int64_t stop = t1;
      if (pending_ && pending_at_ns_ > t && pending_at_ns_ < stop) stop = pending_at_ns_;
      propagate(e, t, stop);
      double u_cost = 0;
      Vector<double, M> dv;
      for (std::size_t j = 0; j < M; ++j) dv[j] = level_average(j, codes_[j]) - u_ref_[j];
      for (std::size_t i = 0; i < M; ++i)
        for (std::size_t k = 0; k < M; ++k) u_cost += dv[i] * cfg_.q2c(i, k) * dv[k];
      cost_.input += u_cost * seconds(stop - t);
      t = stop;
      if (pending_ && t >= pending_at_ns_) {
        for (std::size_t j = 0; j < M; ++j) codes_[j] = pending_codes_[j];
        pending_ = false;
        invalidate();
      }
    }
    x_ = e + x_ref_;
    now_ns_ = t1;
    if (cfg_.process_noise && t1 > start) add_process_noise(t1 - start);
  }

  /// ADC code of output o for the current state plus `noise_volts` (12-bit saturating).
  std::int32_t adc_code(std::size_t o, double noise_volts) const {
    double v = noise_volts;
    for (std::size_t i = 0; i < N; ++i) v += cfg_.c(o, i) * x_[i];
    const double code = std::floor((v - cfg_.adc_min[o]) / cfg_.adc_lsb[o]);
    const double top = std::ldexp(1.0, cfg_.adc_bits) - 1;
    return static_cast<std::int32_t>(std::clamp(code, 0.0, top));
  }

  /// Q_d(Δ) of the process noise (Van Loan).
  Matrix<double, N, N> process_covariance(std::int64_t delta_ns) const {
    const double d = seconds(delta_ns);
    Matrix<double, 2 * N, 2 * N> v;
    v.template set_block<0, 0>(-(cfg_.a * d));
    v.template set_block<0, N>(cfg_.qc * d);
    v.template set_block<N, N>(cfg_.a.transposed() * d);
    Matrix<double, 2 * N, 2 * N> f;
    ONESHOT_ASSERT(matrix_exponential(v, f) == Status::kOk);
    Matrix<double, N, N> q = f.template block<N, N, N, N>().transposed() * f.template block<0, N, N, N>();
    mirror_upper(q);
    return q;
  }

  /// E ∫₀^Δ nᵀ Q1c n ds for the noise path n started at 0 (series, or quadrature when
  /// ‖A‖Δ is large).
  double expected_noise_cost(std::int64_t delta_ns) const {
    const double d = seconds(delta_ns);
    if (2 * a_norm_ * d <= 8) {
      double sum = 0;
      double power = d;  // Δ^{k+1}/(k+1)!
      for (std::size_t k = 0; k < kNoiseTerms; ++k) {
        power *= d / static_cast<double>(k + 2);
        const double term = noise_coeff_[k] * power;
        sum += term;
        if (k > 4 && std::fabs(term) <= 1e-18 * std::fabs(sum)) break;
      }
      return sum;
    }
    // Gauss–Legendre on ∫₀^Δ tr(Q1c Q_d(s)) ds, 16 panels × 5 nodes.
    static constexpr double kX[5] = {-0.9061798459386640, -0.5384693101056831, 0.0, 0.5384693101056831,
                                     0.9061798459386640};
    static constexpr double kW[5] = {0.2369268850561891, 0.4786286704993665, 0.5688888888888889,
                                     0.4786286704993665, 0.2369268850561891};
    double sum = 0;
    const double hp = d / 16;
    for (int p = 0; p < 16; ++p)
      for (int k = 0; k < 5; ++k) {
        const double s = hp * (p + 0.5 + 0.5 * kX[k]);
        const Matrix<double, N, N> prod = cfg_.q1c * process_covariance(static_cast<std::int64_t>(std::llround(s * 1e9)));
        double tr = 0;
        for (std::size_t i = 0; i < N; ++i) tr += prod(i, i);
        sum += 0.5 * hp * kW[k] * tr;
      }
    return sum;
  }

 private:
  static constexpr std::size_t kNoiseTerms = 40;

  struct Segment {
    Matrix<double, N, N> phi;
    Matrix<double, N, M> gamma;
    Matrix<double, kK, kK> g;
  };

  static double seconds(std::int64_t ns) { return static_cast<double>(ns) * 1e-9; }

  double level_average(std::size_t j, std::int32_t code) const {
    return cfg_.v_low[j] + (cfg_.v_high[j] - cfg_.v_low[j]) * code / cfg_.duty_steps;
  }

  std::int64_t high_ns(std::size_t j) const {
    return (static_cast<std::int64_t>(codes_[j]) * cfg_.pwm_period_ns + cfg_.duty_steps / 2) / cfg_.duty_steps;
  }

  void invalidate() { powers_ = 0; }

  const Segment& segment(std::int64_t d_ns) {
    auto it = segments_.find(d_ns);
    if (it != segments_.end()) return it->second;
    if (segments_.size() > 8192) segments_.clear();
    const double d = seconds(d_ns);
    Matrix<double, kK, kK> f;
    f.template set_block<0, 0>(cfg_.a);
    f.template set_block<0, N>(cfg_.b);
    Matrix<double, kK, kK> w;
    w.template set_block<0, 0>(cfg_.q1c);
    Matrix<double, 2 * kK, 2 * kK> v;
    v.template set_block<0, 0>(-(f.transposed() * d));
    v.template set_block<0, kK>(w * d);
    v.template set_block<kK, kK>(f * d);
    Matrix<double, 2 * kK, 2 * kK> e;
    ONESHOT_ASSERT(matrix_exponential(v, e) == Status::kOk);
    const Matrix<double, kK, kK> e22 = e.template block<kK, kK, kK, kK>();
    Segment s;
    s.phi = e22.template block<0, 0, N, N>();
    s.gamma = e22.template block<0, N, N, M>();
    s.g = e22.transposed() * e.template block<0, kK, kK, kK>();
    mirror_upper(s.g);
    return segments_.emplace(d_ns, s).first->second;
  }

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

  void apply_segment(State& e, std::int64_t d, const Vector<double, M>& dv) {
    const Segment& s = segment(d);
    Vector<double, kK> z;
    z.template set_block<0, 0>(e);
    z.template set_block<N, 0>(dv);
    cost_.state += quadratic(s.g, z);
    e = s.phi * e + s.gamma * dv;
  }

  template <std::size_t K>
  static double quadratic(const Matrix<double, K, K>& g, const Vector<double, K>& z) {
    double q = 0;
    for (std::size_t i = 0; i < K; ++i) {
      double row = 0;
      for (std::size_t j = 0; j < K; ++j) row += g(i, j) * z[j];
      q += z[i] * row;
    }
    return q;
  }

  void propagate(State& e, std::int64_t t0, std::int64_t t1) {
    const std::int64_t period = cfg_.pwm_period_ns;
    const std::int64_t base0 = (t0 / period) * period;
    const std::int64_t boundary = base0 + period;
    if (t1 <= boundary) {
      for_each_segment(base0, t0, t1, [&](std::int64_t d, const Vector<double, M>& dv) { apply_segment(e, d, dv); });
      return;
    }
    for_each_segment(base0, t0, boundary, [&](std::int64_t d, const Vector<double, M>& dv) { apply_segment(e, d, dv); });
    const std::int64_t n = (t1 - boundary) / period;
    if (n > 0) full_periods(e, n);
    const std::int64_t tail = boundary + n * period;
    for_each_segment(tail, tail, t1, [&](std::int64_t d, const Vector<double, M>& dv) { apply_segment(e, d, dv); });
  }

  /// The per-period map S and cost C on w = [e; 1] for the current duties and set-point.
  void build_period() {
    Aug s = Aug::identity();
    Aug c;
    for_each_segment(0, 0, cfg_.pwm_period_ns, [&](std::int64_t d, const Vector<double, M>& dv) {
      const Segment& seg = segment(d);
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

  void full_periods(State& e, std::int64_t n) {
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
        cost_.state += quadratic(c_pow_[j], w);
        w = s_pow_[j] * w;
      }
    }
    e = w.template block<0, 0, N, 1>();
  }

  void add_process_noise(std::int64_t delta_ns) {
    const Matrix<double, N, N> q = process_covariance(delta_ns);
    // Cholesky with zero pivots allowed (Q_d may be singular).
    Matrix<double, N, N> l;
    for (std::size_t j = 0; j < N; ++j) {
      double d = q(j, j);
      for (std::size_t k = 0; k < j; ++k) d -= l(j, k) * l(j, k);
      l(j, j) = d > 0 ? std::sqrt(d) : 0;
      for (std::size_t i = j + 1; i < N; ++i) {
        double s = q(i, j);
        for (std::size_t k = 0; k < j; ++k) s -= l(i, k) * l(j, k);
        l(i, j) = l(j, j) > 0 ? s / l(j, j) : 0;
      }
    }
    State w;
    for (std::size_t i = 0; i < N; ++i) w[i] = noise_.normal();
    x_ = x_ + l * w;
    cost_.noise += expected_noise_cost(delta_ns);
  }

  static constexpr std::size_t kMaxPowers = 48;

  CircuitConfig<N, M, P> cfg_;
  RandomStream noise_;
  std::int64_t now_ns_ = 0;
  State x_{};
  Vector<double, P> r_{};
  State x_ref_{};
  Vector<double, M> u_ref_{};
  std::int32_t codes_[M] = {};
  std::int32_t pending_codes_[M] = {};
  bool pending_ = false;
  std::int64_t pending_at_ns_ = 0;
  CostBreakdown cost_{};
  double noise_coeff_[kNoiseTerms] = {};
  double a_norm_ = 0;
  std::unordered_map<std::int64_t, Segment> segments_;
  Aug s_pow_[kMaxPowers];
  Aug c_pow_[kMaxPowers];
  std::size_t powers_ = 0;
};

}  // namespace oneshot::sim
