/// @file linear_tracker.hpp
/// @brief The linear board's plant (the board's continuous model, the input a real value held
///        between actuations) and its analytic tracker (mean and covariance of the closed loop).
///
/// Tracker state z = [x (N); u held at the plant (M); x̂ (N); u_last (M); u_prev (M)] (the
/// estimator memory of estimator_memory.hpp). Events:
///  - job at t_s:   y = C x + v, v ~ N(0, R); [x̂; u_last] ← the job's affine map of
///                  [y; x̂; u_last; u_prev], probed on copies of the estimator taken before
///                  the job (engine/affine_probe.hpp); u_prev ← u_last (old);
///  - actuation:    u ← u_last (one-shot at t_{k+1}, standard at t_s + exec);
///  - flow:         the plant over the interval with u held (engine JumpLinearCost).
/// Every mean is checked against the noise-free simulated run (1e-9 of the signal), and a run
/// whose mean input leaves the actuator range is refused: the board would clamp it.
#pragma once

#include <cmath>
#include <cstddef>
#include <memory>
#include <string>
#include <vector>

#include "oneshot/engine/affine_probe.hpp"
#include "oneshot/engine/exact_segment.hpp"
#include "oneshot/engine/jump_linear_cost.hpp"
#include "oneshot/engine/process_noise.hpp"
#include "oneshot/engine/quadratic_form.hpp"
#include "oneshot/engine/random_stream.hpp"
#include "oneshot/engine/sim_time.hpp"
#include "oneshot/matrix.hpp"
#include "linear_board.hpp"

namespace oneshot::sim {

/// Interval maps (keyed by A, B, Q1c) and process-noise terms (keyed by A, Q_c, Q1c) shared by
/// the runs of one thread: the matrix exponentials per interval length dominate a run, and the
/// same lengths recur from run to run. The values per length do not depend on the cache.
/// Entries are never evicted (the keys are the few plants of a study: the run's plant, with
/// and without process noise), so a reference handed out stays valid for the thread's life.
template <std::size_t N, std::size_t M>
class SharedCaches {
 public:
  /// The interval maps of plant `p`.
  static engine::ExactSegmentCache<N, M>& segments(const engine::JumpLinearPlant<N, M>& p) {
    thread_local std::vector<std::unique_ptr<SegmentsEntry>> all;
    for (auto& e : all)
      if (same(e->a, p.a) && same(e->b, p.b) && same(e->q1c, p.q1c)) return e->cache;
    all.push_back(std::make_unique<SegmentsEntry>(SegmentsEntry{p.a, p.b, p.q1c, {p.a, p.b, p.q1c}}));
    return all.back()->cache;
  }
  /// The process-noise terms of plant `p`.
  static engine::ProcessNoise<N>& noise(const engine::JumpLinearPlant<N, M>& p) {
    thread_local std::vector<std::unique_ptr<NoiseEntry>> all;
    for (auto& e : all)
      if (same(e->a, p.a) && same(e->qc, p.qc) && same(e->q1c, p.q1c)) return e->cache;
    all.push_back(std::make_unique<NoiseEntry>(NoiseEntry{p.a, p.qc, p.q1c, {p.a, p.qc, p.q1c}}));
    return all.back()->cache;
  }

 private:
  struct SegmentsEntry {
    Matrix<double, N, N> a;
    Matrix<double, N, M> b;
    Matrix<double, N, N> q1c;
    engine::ExactSegmentCache<N, M> cache;
  };
  struct NoiseEntry {
    Matrix<double, N, N> a;
    Matrix<double, N, N> qc;
    Matrix<double, N, N> q1c;
    engine::ProcessNoise<N> cache;
  };
  template <std::size_t R, std::size_t C>
  static bool same(const Matrix<double, R, C>& x, const Matrix<double, R, C>& y) {
    for (std::size_t i = 0; i < R; ++i)
      for (std::size_t j = 0; j < C; ++j)
        if (!(x(i, j) == y(i, j))) return false;
    return true;
  }
};

/// The plant of the linear board: exact flow with the input held, one N(0, Q_d(Δ)) draw per
/// interval (the board's "process" stream), the cost as the board's (expected noise path cost).
template <std::size_t N, std::size_t M>
class LinearPlant {
 public:
  /// Plant and cost (engine units); `noise` feeds the process noise when `noisy`.
  LinearPlant(const engine::JumpLinearPlant<N, M>& p, bool noisy, engine::RandomStream noise)
      : p_(p),
        noisy_(noisy),
        rng_(std::move(noise)),
        noise_(SharedCaches<N, M>::noise(p)),
        segments_(SharedCaches<N, M>::segments(p)) {}

  /// Advances to t1 ≥ now.
  void advance_to(engine::SimTime t1) {
    const engine::Duration d = t1 - now_;
    now_ = t1;
    if (d.count() <= 0) return;
    const auto& seg = segments_.get(d.count());
    Vector<double, N + M> q;
    for (std::size_t i = 0; i < N; ++i) q[i] = x_[i] - x_ref_[i];
    for (std::size_t j = 0; j < M; ++j) q[N + j] = u_[j] - u_ref_[j];
    const Vector<double, M> du = q.template block<N, 0, M, 1>();
    cost_ += engine::quadratic_form(seg.g, q) + engine::quadratic_form(p_.q2c, du) * engine::to_seconds(d);
    const Vector<double, N> e = q.template block<0, 0, N, 1>();
    x_ = seg.phi * e + seg.gamma * du + x_ref_;
    if (noisy_) {
      x_ = x_ + noise_.draw(d, rng_);
      cost_ += noise_.interval_cost(d);
    }
  }
  /// The reference of the cost from now on.
  void set_reference(const Vector<double, N>& x_ref, const Vector<double, M>& u_ref) {
    x_ref_ = x_ref;
    u_ref_ = u_ref;
  }
  /// The input held from now on.
  void apply(const Vector<double, M>& u) { u_ = u; }
  const Vector<double, N>& state() const { return x_; }  ///< x.
  const Vector<double, M>& input() const { return u_; }  ///< u held.
  double cost() const { return cost_; }                  ///< J so far.

 private:
  engine::JumpLinearPlant<N, M> p_;
  bool noisy_;
  engine::RandomStream rng_;
  engine::ProcessNoise<N>& noise_;
  engine::ExactSegmentCache<N, M>& segments_;
  engine::SimTime now_{0};
  Vector<double, N> x_{};
  Vector<double, M> u_{};
  Vector<double, N> x_ref_{};
  Vector<double, M> u_ref_{};
  double cost_ = 0;
};

/// Mean and covariance of z through a linear-board run, and the exact expected cost.
template <std::size_t N, std::size_t M, std::size_t P>
class LinearTracker {
 public:
  static constexpr std::size_t kK = 2 * N + 3 * M;  ///< Size of z.
  static constexpr std::size_t kU = N;               ///< Offset of u held.
  static constexpr std::size_t kH = N + M;           ///< Offset of x̂.
  static constexpr std::size_t kL = 2 * N + M;       ///< Offset of u_last.
  static constexpr std::size_t kV = 2 * N + 2 * M;   ///< Offset of u_prev.
  static constexpr std::size_t kW = P + N + 2 * M;   ///< Inputs of a job: [y; x̂; u_last; u_prev].
  using Jlc = engine::JumpLinearCost<N, M, kK>;      ///< The engine's propagation.
  using Map = typename Jlc::Map;                     ///< Event map E.
  using Z = typename Jlc::Z;                         ///< z.

  /// Plant (Q_c zero: noise-free), C, R (zero: noise-free), the input at power-on (held and
  /// in the estimator's memory), the actuator range.
  LinearTracker(const engine::JumpLinearPlant<N, M>& plant, const Matrix<double, P, N>& c, const Matrix<double, P, P>& r,
                const Vector<double, M>& u0, const Vector<double, M>& u_min, const Vector<double, M>& u_max)
      : jl_(plant, SharedCaches<N, M>::segments(plant), SharedCaches<N, M>::noise(plant)), c_(c), r_(r), u_min_(u_min), u_max_(u_max) {
    Z m{};
    for (std::size_t j = 0; j < M; ++j) m[kU + j] = m[kL + j] = m[kV + j] = u0[j];
    jl_.reset(m, typename Jlc::Cov{});
  }

  /// Flow to t.
  void flow_to(engine::SimTime t) {
    jl_.flow(t - now_);
    now_ = t;
  }
  /// The cost's reference from now on.
  void set_reference(const Vector<double, N>& x_ref, const Vector<double, M>& u_ref) { jl_.set_reference(x_ref, u_ref); }

  /// A job: `eval(w)` runs the job on a copy of the estimator as it was before the job with
  /// inputs w = [y; x̂; u_last; u_prev] and returns [x̂ after; u]; `x_sim`, `u_sim` are what
  /// the simulated (noise-free) job produced.
  template <typename Eval>
  void job(const Eval& eval, const Vector<double, N>& x_sim, const Vector<double, M>& u_sim) {
    const Z& m = jl_.mean();
    Vector<double, kW> w0;
    for (std::size_t p = 0; p < P; ++p) {
      double y = 0;
      for (std::size_t i = 0; i < N; ++i) y += c_(p, i) * m[i];
      w0[p] = y;
    }
    for (std::size_t i = 0; i < N; ++i) w0[P + i] = m[kH + i];
    for (std::size_t j = 0; j < M; ++j) {
      w0[P + N + j] = m[kL + j];
      w0[P + N + M + j] = m[kV + j];
    }
    Matrix<double, N + M, kW> jac;
    Vector<double, N + M> b;
    engine::probe_affine<kW, N + M>(eval, w0, 1.0, jac, b);
    Map e = Map::identity();
    Matrix<double, kK, P> f;
    Z g{};
    for (std::size_t o = 0; o < N + M; ++o) {
      const std::size_t row = o < N ? kH + o : kL + (o - N);
      for (std::size_t j = 0; j < kK; ++j) e(row, j) = 0;
      g[row] = b[o];
      for (std::size_t p = 0; p < P; ++p) {
        f(row, p) = jac(o, p);
        for (std::size_t i = 0; i < N; ++i) e(row, i) += jac(o, p) * c_(p, i);
      }
      for (std::size_t i = 0; i < N; ++i) e(row, kH + i) += jac(o, P + i);
      for (std::size_t j = 0; j < M; ++j) {
        e(row, kL + j) += jac(o, P + N + j);
        e(row, kV + j) += jac(o, P + N + M + j);
      }
    }
    for (std::size_t j = 0; j < M; ++j) {  // u_prev ← u_last (old)
      for (std::size_t i = 0; i < kK; ++i) e(kV + j, i) = 0;
      e(kV + j, kL + j) = 1;
    }
    jl_.jump(e, f, g, r_);
    for (std::size_t i = 0; i < N; ++i) check(jl_.mean()[kH + i], x_sim[i]);
    for (std::size_t j = 0; j < M; ++j) {
      const double u = jl_.mean()[kL + j];
      check(u, u_sim[j]);
      if (!(u >= u_min_[j] && u <= u_max_[j])) refuse(kLinearRefusalRange);
    }
  }

  /// The plant takes u_last; `u_sim` is what the simulated plant took.
  void apply(const Vector<double, M>& u_sim) {
    Map e = Map::identity();
    for (std::size_t j = 0; j < M; ++j) {
      e(kU + j, kU + j) = 0;
      e(kU + j, kL + j) = 1;
    }
    jl_.jump(e, Z{});
    for (std::size_t j = 0; j < M; ++j) check(jl_.mean()[kU + j], u_sim[j]);
  }

  /// Refuses the run with `reason` (the first reason is kept).
  void refuse(const std::string& reason) {
    if (refusal_.empty()) refusal_ = reason;
  }
  const std::string& refusal() const { return refusal_; }         ///< "" unless refused.
  const engine::ExpectedCost& cost() const { return jl_.cost(); }  ///< Expected cost so far.
  double mismatch() const { return mismatch_; }                   ///< Largest |mean − simulated| / scale.
  const Z& mean() const { return jl_.mean(); }                    ///< E z now.
  const typename Jlc::Cov& covariance() const { return jl_.covariance(); }  ///< Cov z now.

 private:
  void check(double mean, double sim) {
    const double d = std::fabs(mean - sim) / std::fmax(1.0, std::fabs(sim));
    mismatch_ = std::fmax(mismatch_, d);
    if (!(d <= 1e-9)) refuse(kLinearRefusalMismatch);
  }

  Jlc jl_;
  Matrix<double, P, N> c_;
  Matrix<double, P, P> r_;
  Vector<double, M> u_min_;
  Vector<double, M> u_max_;
  engine::SimTime now_{0};
  double mismatch_ = 0;
  std::string refusal_;
};

}  // namespace oneshot::sim
