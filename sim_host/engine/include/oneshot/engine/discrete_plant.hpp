/// @file discrete_plant.hpp
/// @brief A discrete linear plant stepped at its period, with a per-step cost.
///
///     x_{k+1} = Φ x_k + Γ u_k + Γ_w d_k + w_k,   y_k = C x_k,   w_k ~ N(0, Q) i.i.d.
///
/// Step k spans [k T, (k+1) T). Its input u_k is the one in force at the end of instant
/// k T, after every event of that instant (latch_input(), run in EventClass::kLatch); the
/// step itself runs first at (k+1) T (EventClass::kPlantStep), so every sensor sampling at
/// (k+1) T reads x_{k+1}. attach_discrete_plant() schedules both. The cost of step k is
///     e_kᵀ Q1 e_k + ũ_kᵀ Q2 ũ_k,   e = x − x_ref, ũ = u − u_ref (reference in force at k T).
/// Noise w_k is drawn once per step from the plant's own stream.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "oneshot/assert_handler.hpp"
#include "oneshot/engine/cost.hpp"
#include "oneshot/engine/kernel.hpp"
#include "oneshot/engine/psd_math.hpp"
#include "oneshot/engine/quadratic_form.hpp"
#include "oneshot/engine/random_stream.hpp"
#include "oneshot/engine/sim_time.hpp"
#include "oneshot/engine/trace_sample.hpp"
#include "oneshot/matrix.hpp"

namespace oneshot::engine {

/// Parameters of a DiscretePlant.
template <std::size_t N, std::size_t M, std::size_t P, std::size_t W>
struct DiscretePlantConfig {
  Matrix<double, N, N> phi;      ///< Φ.
  Matrix<double, N, M> gamma;    ///< Γ.
  Matrix<double, N, W> gamma_w;  ///< Γ_w (disturbance input; zero when absent).
  Matrix<double, P, N> c;        ///< C.
  Matrix<double, N, N> q;        ///< Q: covariance of w_k per step.
  Matrix<double, N, N> q1;       ///< Per-step cost weight on e.
  Matrix<double, M, M> q2;       ///< Per-step cost weight on ũ.
  Duration period{0};            ///< T.
  bool process_noise = true;     ///< Draw w_k.
};

/// Discrete LTI plant with n = N states, m = M inputs, p = P outputs, W disturbance inputs.
template <std::size_t N, std::size_t M, std::size_t P, std::size_t W = 1>
class DiscretePlant {
 public:
  static constexpr std::size_t kStates = N;         ///< n.
  static constexpr std::size_t kInputs = M;         ///< m.
  static constexpr std::size_t kOutputs = P;        ///< p.
  static constexpr std::size_t kDisturbances = W;   ///< Columns of Γ_w.
  using State = Vector<double, N>;
  using Input = Vector<double, M>;
  using Output = Vector<double, P>;
  using Disturbance = Vector<double, W>;
  using Sample = TraceSample<N, M, P>;

  /// Plant at step 0, x = 0; `noise` feeds w_k.
  DiscretePlant(const DiscretePlantConfig<N, M, P, W>& config, RandomStream noise)
      : cfg_(config), noise_rng_(std::move(noise)), chol_(psd_cholesky(config.q)) {
    ONESHOT_ASSERT(cfg_.period.count() > 0);
  }

  /// Steps taken.
  std::int64_t step_index() const { return k_; }
  /// True state x_k.
  const State& state() const { return x_; }
  /// Sets the state (initial conditions).
  void set_state(const State& x) { x_ = x; }
  /// Noise-free output C x_k.
  Output output() const { return cfg_.c * x_; }
  /// Input in force (not yet latched).
  const Input& input() const { return u_; }
  /// Input latched for the current step.
  const Input& latched_input() const { return u_latched_; }
  /// Cost so far.
  const CostBreakdown& cost() const { return cost_; }
  /// The configuration.
  const DiscretePlantConfig<N, M, P, W>& config() const { return cfg_; }
  /// States x_0, x_1, … when recording (record_states).
  const std::vector<Sample>& trace() const { return trace_; }

  /// Holds u from now on (takes effect at the next latch).
  void set_input(const Input& u) { u_ = u; }
  /// Holds d from now on (takes effect at the next latch).
  void set_disturbance(const Disturbance& d) { d_ = d; }
  /// Reference of the cost from now on.
  void set_reference(const State& x_ref, const Input& u_ref) {
    x_ref_ = x_ref;
    u_ref_ = u_ref;
  }
  /// Keeps x_k of every step (the state trace of a discrete plant).
  void record_states() {
    recording_ = true;
    trace_.push_back(Sample{Duration{k_ * cfg_.period.count()}, x_, cfg_.c * x_ref_, u_});
  }

  /// Latches u_k, d_k and the reference of step k (end of instant k T).
  void latch_input() {
    u_latched_ = u_;
    d_latched_ = d_;
    e_ref_ = x_ref_;
    u_ref_latched_ = u_ref_;
  }

  /// x_{k+1} = Φ x_k + Γ u_k + Γ_w d_k + w_k, and the cost of step k.
  void step() {
    const State e = x_ - e_ref_;
    const Input du = u_latched_ - u_ref_latched_;
    cost_.state += quadratic_form(cfg_.q1, e);
    cost_.input += quadratic_form(cfg_.q2, du);
    x_ = cfg_.phi * x_ + cfg_.gamma * u_latched_ + cfg_.gamma_w * d_latched_;
    if (cfg_.process_noise) {
      State w;
      for (std::size_t i = 0; i < N; ++i) w[i] = noise_rng_.normal();
      x_ = x_ + chol_ * w;
    }
    ++k_;
    if (recording_) trace_.push_back(Sample{Duration{k_ * cfg_.period.count()}, x_, cfg_.c * x_ref_, u_latched_});
  }

 private:
  DiscretePlantConfig<N, M, P, W> cfg_;
  RandomStream noise_rng_;
  Matrix<double, N, N> chol_;
  std::int64_t k_ = 0;
  State x_{};
  Input u_{};
  Disturbance d_{};
  Input u_latched_{};
  Disturbance d_latched_{};
  State x_ref_{};
  Input u_ref_{};
  State e_ref_{};
  Input u_ref_latched_{};
  CostBreakdown cost_{};
  bool recording_ = false;
  std::vector<Sample> trace_;
};

/// Schedules the latch (kLatch at k T) and the step (kPlantStep at (k+1) T) of every period
/// k with (k+1) T ≤ end; each step schedules the next (the queue holds two events, not 2n).
template <typename Plant>
void attach_discrete_plant(Kernel& kernel, Plant& plant, SimTime end) {
  const Duration period = plant.config().period;
  const HandlerId latch = kernel.add_handler("discrete plant latch", [&plant](std::uint64_t) { plant.latch_input(); });
  auto step_id = std::make_shared<HandlerId>(0);
  *step_id = kernel.add_handler("discrete plant step", [&kernel, &plant, latch, step_id, period, end](std::uint64_t) {
    plant.step();
    const SimTime next_end = kernel.now() + period;
    if (next_end > end) return;
    kernel.schedule(kernel.now(), EventClass::kLatch, latch);
    kernel.schedule(next_end, EventClass::kPlantStep, *step_id);
  });
  if (period > end) return;
  kernel.schedule(kernel.now(), EventClass::kLatch, latch);
  kernel.schedule(kernel.now() + period, EventClass::kPlantStep, *step_id);
}

}  // namespace oneshot::engine
