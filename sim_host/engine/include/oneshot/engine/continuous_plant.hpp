/// @file continuous_plant.hpp
/// @brief A continuous linear plant propagated exactly between events with piecewise-
///        constant input, its control cost integrated exactly along the true state.
///
///     ẋ = A x + B u + B_w d + w,   y = C x,   E[w(t) w(s)ᵀ] = Q_c δ(t − s)
///
/// u (m inputs) and d (W disturbance inputs through B_w) are held between events. In
/// deviation coordinates e = x − x_ref, ũ = u − u_ref (the reference must be an
/// equilibrium, A x_ref + B u_ref = 0), an interval of length Δ is the exact map
///     e(Δ) = Φ(Δ) e + Γ(Δ) ũ + Γ_w(Δ) d,   ∫₀^Δ eᵀQ1c e ds = zᵀ G(Δ) z,  z = [e; ũ; d],
/// from one Van Loan exponential of [[−Fᵀ, blkdiag(Q1c, 0, 0)], [0, F]] Δ with
/// F = [[A, B, B_w], [0, 0, 0], [0, 0, 0]], cached per interval length; the input term is
/// ũᵀQ2c ũ Δ. Each advance_to() is a physical event: one exact N(0, Q_d(Δ)) draw and the
/// expected cost of the noise path (process_noise.hpp). A recorded trace is bridged from
/// its own stream and never changes the run.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <vector>

#include "oneshot/assert_handler.hpp"
#include "oneshot/engine/cost.hpp"
#include "oneshot/engine/exact_segment.hpp"
#include "oneshot/engine/process_noise.hpp"
#include "oneshot/engine/random_stream.hpp"
#include "oneshot/engine/shared_plant_caches.hpp"
#include "oneshot/engine/sim_time.hpp"
#include "oneshot/engine/trace_sample.hpp"
#include "oneshot/matrix.hpp"

namespace oneshot::engine {

/// Parameters of a ContinuousPlant (SI units).
template <std::size_t N, std::size_t M, std::size_t P, std::size_t W>
struct ContinuousPlantConfig {
  Matrix<double, N, N> a;    ///< A (1/s).
  Matrix<double, N, M> b;    ///< B.
  Matrix<double, N, W> bw;   ///< B_w (disturbance input; zero when absent).
  Matrix<double, P, N> c;    ///< C.
  Matrix<double, N, N> qc;   ///< Process noise intensity Q_c (state units²/s).
  Matrix<double, N, N> q1c;  ///< Cost weight on e.
  Matrix<double, M, M> q2c;  ///< Cost weight on ũ.
  bool process_noise = true; ///< Inject process noise.
  /// States whose noise is drawn (the first ones; N: all). A plant embedded in a larger shape
  /// (its padded states inert, Q_c 0 there) draws the normals of its own n: the same run.
  std::size_t active_states = N;
};

/// Exactly propagated continuous LTI plant with n = N states, m = M inputs, p = P outputs
/// and W disturbance inputs.
template <std::size_t N, std::size_t M, std::size_t P, std::size_t W = 1>
class ContinuousPlant {
 public:
  static constexpr std::size_t kStates = N;         ///< n.
  static constexpr std::size_t kInputs = M;         ///< m.
  static constexpr std::size_t kOutputs = P;        ///< p.
  static constexpr std::size_t kDisturbances = W;   ///< Columns of B_w.
  static constexpr std::size_t kK = N + M + W;
  using State = Vector<double, N>;
  using Input = Vector<double, M>;
  using Output = Vector<double, P>;
  using Disturbance = Vector<double, W>;
  using Sample = TraceSample<N, M, P>;

  /// Plant at t = 0, x = 0, u = 0, d = 0, reference 0; `noise` feeds the process noise.
  ContinuousPlant(const ContinuousPlantConfig<N, M, P, W>& config, RandomStream noise)
      : cfg_(config), noise_rng_(std::move(noise)), noise_(config.a, config.qc, config.q1c),
        segments_(config.a, held_input_matrix(config), config.q1c) {}

  /// The same, with the interval maps and noise terms taken from (and added to) `pool`'s caches
  /// for this plant (nullptr: its own). The values per interval length do not depend on the
  /// cache: the same run, bit for bit. A caller passing a pool includes plant_cache_pool.hpp.
  ContinuousPlant(const ContinuousPlantConfig<N, M, P, W>& config, RandomStream noise, PlantCachePool<N, M + W>* pool)
      : ContinuousPlant(config, std::move(noise)) {
    if (pool != nullptr) shared_ = pool->take(config.a, held_input_matrix(config), config.qc, config.q1c, config.process_noise);
  }

  /// Current time.
  SimTime now() const { return now_; }
  /// True state.
  const State& state() const { return x_; }
  /// Sets the state (initial conditions).
  void set_state(const State& x) { x_ = x; }
  /// Noise-free output C x now.
  Output output() const { return cfg_.c * x_; }
  /// Input in force.
  const Input& input() const { return u_; }
  /// Cost so far.
  const CostBreakdown& cost() const { return cost_; }
  /// Recorded trace.
  const std::vector<Sample>& trace() const { return trace_; }
  /// The configuration.
  const ContinuousPlantConfig<N, M, P, W>& config() const { return cfg_; }

  /// Holds u from now on (call advance_to(now) first: the plant must be at the event).
  void set_input(const Input& u) { u_ = u; }
  /// Holds the disturbance d from now on.
  void set_disturbance(const Disturbance& d) { d_ = d; }
  /// Reference (x_ref, u_ref) of the cost from now on; std::invalid_argument unless
  /// A x_ref + B u_ref = 0 (to 1e-9 of the terms' size).
  void set_reference(const State& x_ref, const Input& u_ref) {
    const State res = cfg_.a * x_ref + cfg_.b * u_ref;
    double size = 0;
    double err = 0;
    for (std::size_t i = 0; i < N; ++i) {
      err = std::fmax(err, std::fabs(res[i]));
      for (std::size_t j = 0; j < N; ++j) size = std::fmax(size, std::fabs(cfg_.a(i, j) * x_ref[j]));
      for (std::size_t j = 0; j < M; ++j) size = std::fmax(size, std::fabs(cfg_.b(i, j) * u_ref[j]));
    }
    if (err > 1e-9 * size) {
      throw std::invalid_argument("continuous plant: the reference is not an equilibrium (|A x_ref + B u_ref| = " +
                                  std::to_string(err) + ")");
    }
    x_ref_ = x_ref;
    u_ref_ = u_ref;
  }
  /// x_ref in force.
  const State& reference_state() const { return x_ref_; }

  /// Records the true state every `step` from now on (bridge draws from `rng`).
  void record_trace(Duration step, RandomStream rng) {
    ONESHOT_ASSERT(step.count() > 0);
    trace_step_ = step;
    trace_rng_ = std::move(rng);
    trace_.push_back(Sample{now_, x_, x_ref_c(), u_});
    trace_next_ = now_ + step;
  }

  /// Advances to t1 ≥ now: exact propagation, cost, then the interval's process noise.
  void advance_to(SimTime t1) {
    ONESHOT_ASSERT(t1 >= now_);
    if (t1 == now_) return;
    const SimTime start = now_;
    const Duration delta = t1 - start;
    const State e0 = x_ - x_ref_;
    const Input du = u_ - u_ref_;
    const std::size_t first_new = trace_.size();
    while (trace_step_.count() > 0 && trace_next_ <= t1) {
      trace_.push_back(Sample{trace_next_, propagated(segments().get((trace_next_ - start).count()), e0, du), x_ref_c(), u_});
      trace_next_ += trace_step_;
    }
    const Segment& seg = segments().get(delta.count());
    Vector<double, kK> z;
    z.template set_block<0, 0>(e0);
    z.template set_block<N, 0>(du);
    z.template set_block<N + M, 0>(d_);
    cost_.state += quadratic_form(seg.g, z);
    double u_cost = 0;
    for (std::size_t i = 0; i < M; ++i)
      for (std::size_t k = 0; k < M; ++k) u_cost += du[i] * cfg_.q2c(i, k) * du[k];
    cost_.input += u_cost * to_seconds(delta);
    x_ = propagated(seg, e0, du);
    now_ = t1;
    if (!cfg_.process_noise) return;
    ProcessNoise<N>& terms = noise();
    const State n_end = terms.draw(delta, noise_rng_, cfg_.active_states);
    x_ = x_ + n_end;
    cost_.noise += terms.interval_cost(delta);
    bridge_trace_noise(trace_, first_new, start, t1, n_end, terms, trace_rng_, cfg_.active_states);
  }

  /// Q_d(Δ) of the process noise.
  Matrix<double, N, N> process_covariance(Duration delta) const { return noise_.covariance(delta); }

 private:
  /// The interval maps in use (the pool's or the plant's own).
  ExactSegmentCache<N, M + W>& segments() { return shared_.segments ? *shared_.segments : segments_; }
  /// The noise terms in use.
  ProcessNoise<N>& noise() { return shared_.noise ? *shared_.noise : noise_; }
  Output x_ref_c() const { return cfg_.c * x_ref_; }
  using Segment = ExactSegment<N, M + W>;
  /// [B, B_w]: the columns held over an interval.
  static Matrix<double, N, M + W> held_input_matrix(const ContinuousPlantConfig<N, M, P, W>& c) {
    Matrix<double, N, M + W> b;
    b.template set_block<0, 0>(c.b);
    b.template set_block<0, M>(c.bw);
    return b;
  }
  /// Φ e0 + Γ ũ + Γ_w d + x_ref.
  State propagated(const Segment& s, const State& e0, const Input& du) const {
    const Matrix<double, N, M> gamma = s.gamma.template block<0, 0, N, M>();
    const Matrix<double, N, W> gamma_w = s.gamma.template block<0, M, N, W>();
    return s.phi * e0 + gamma * du + gamma_w * d_ + x_ref_;
  }

  ContinuousPlantConfig<N, M, P, W> cfg_;
  RandomStream noise_rng_;
  ProcessNoise<N> noise_;
  SimTime now_{0};
  State x_{};
  Input u_{};
  Disturbance d_{};
  State x_ref_{};
  Input u_ref_{};
  CostBreakdown cost_{};
  ExactSegmentCache<N, M + W> segments_;
  SharedPlantCaches<N, M + W> shared_;
  Duration trace_step_{0};
  SimTime trace_next_{0};
  RandomStream trace_rng_{0, "trace"};
  std::vector<Sample> trace_;
};

}  // namespace oneshot::engine
