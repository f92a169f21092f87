/// @file jump_linear_cost.hpp
/// @brief Exact expected cost over process and measurement noise of a linear closed loop
///        for one given timing sequence (the JitterTime method): mean and covariance of the
///        closed-loop state propagated through flows and event jumps, cost in closed form.
///
/// Closed-loop state z (K entries) = [x (N, the continuous plant); u (M, the inputs held at
/// the plant); registers (controller and estimator states, values in flight)].
/// Between events (length Δ) the plant flows with the inputs held, the registers stay:
///     x⁺ = x_ref + Φ(Δ)(x − x_ref) + Γ(Δ)(u − u_ref) + n,   n ~ N(0, Q_d(Δ)),
/// so m⁺ = T m (+ the reference terms), Σ⁺ = T Σ Tᵀ + blkdiag(Q_d(Δ), 0), T = I with the
/// x rows replaced by [Φ Γ 0]. The cost of the interval, q = [x − x_ref; u − u_ref]:
///     E ∫ eᵀQ1c e + ũᵀQ2c ũ ds = μ_qᵀ G(Δ) μ_q + tr(G(Δ) Σ_q) + Δ (μ_ũᵀQ2c μ_ũ + tr(Q2c Σ_u))
///                               + ∫₀^Δ tr(Q1c Q_d(s)) ds
/// (G from exact_segment.hpp, the last term from process_noise.hpp; all cached per Δ).
/// At an event the study supplies the affine map z⁺ = E z + F v + g, v ~ N(0, R) drawn
/// there (measurement noise):  m⁺ = E m + g,  Σ⁺ = E Σ Eᵀ + F R Fᵀ.
/// A discrete cost at an event, E[(z − c)ᵀW(z − c)] = (m − c)ᵀW(m − c) + tr(WΣ), is
/// add_event_cost(). The engine knows no study: the event maps come from the caller.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>

#include "oneshot/engine/exact_segment.hpp"
#include "oneshot/engine/process_noise.hpp"
#include "oneshot/engine/quadratic_form.hpp"
#include "oneshot/engine/sim_time.hpp"
#include "oneshot/matrix.hpp"

namespace oneshot::engine {

/// Plant and cost of a JumpLinearCost (SI units).
template <std::size_t N, std::size_t M>
struct JumpLinearPlant {
  Matrix<double, N, N> a;    ///< A (1/s).
  Matrix<double, N, M> b;    ///< B.
  Matrix<double, N, N> qc;   ///< Process noise intensity Q_c (zero: noise-free).
  Matrix<double, N, N> q1c;  ///< Cost weight on e = x − x_ref.
  Matrix<double, M, M> q2c;  ///< Cost weight on ũ = u − u_ref.
};

/// Expected cost split by origin (their sum is E[J]).
struct ExpectedCost {
  double mean = 0;        ///< Cost of the mean trajectory (μ_qᵀ G μ_q + Δ μ_ũᵀQ2c μ_ũ): the noise-free cost.
  double covariance = 0;  ///< tr(G Σ_q) + Δ tr(Q2c Σ_u): the spread of z at the interval starts.
  double noise_path = 0;  ///< ∫ tr(Q1c Q_d(s)) ds inside the intervals.
  /// E[J].
  double total() const { return mean + covariance + noise_path; }
};

/// Mean and covariance of the closed-loop state z (K ≥ N + M) and the exact expected cost.
template <std::size_t N, std::size_t M, std::size_t K>
class JumpLinearCost {
  static_assert(K >= N + M, "z holds the plant state and the held inputs first");

 public:
  static constexpr std::size_t kQ = N + M;  ///< Size of q = [e; ũ].
  using Z = Vector<double, K>;              ///< Closed-loop state.
  using Cov = Matrix<double, K, K>;         ///< Its covariance.
  using Map = Matrix<double, K, K>;         ///< Event map E.

  /// Plant, cost and noise; z starts at zero with zero covariance, reference zero.
  explicit JumpLinearCost(const JumpLinearPlant<N, M>& p)
      : plant_(p), noise_(p.a, p.qc, p.q1c), segments_(p.a, p.b, p.q1c) {
    for (std::size_t i = 0; i < N; ++i)
      for (std::size_t j = 0; j < N; ++j) noisy_ = noisy_ || p.qc(i, j) != 0;
  }

  /// The same, with the interval maps and noise terms taken from (and added to) caches shared
  /// by many runs of the plant `p` (built from its A, B, Q1c and A, Q_c, Q1c; they must outlive
  /// this object). The values per interval length do not depend on the cache: same results.
  JumpLinearCost(const JumpLinearPlant<N, M>& p, ExactSegmentCache<N, M>& segments, ProcessNoise<N>& noise)
      : JumpLinearCost(p) {
    shared_segments_ = &segments;
    shared_noise_ = &noise;
  }

  /// Mean m and covariance Σ of z now.
  void reset(const Z& m, const Cov& s) {
    m_ = m;
    s_ = s;
  }
  /// Starts the cost from zero again (the state and the caches stay): one period's cost at a time.
  void clear_cost() { cost_ = {}; }
  /// The reference (x_ref, u_ref) of the cost from now on (must be an equilibrium of the plant).
  void set_reference(const Vector<double, N>& x_ref, const Vector<double, M>& u_ref) {
    x_ref_ = x_ref;
    u_ref_ = u_ref;
  }

  /// Flow over `delta` (≥ 0): adds the interval's expected cost, then propagates m and Σ.
  void flow(Duration delta) {
    if (delta.count() <= 0) return;
    const auto& seg = (shared_segments_ != nullptr ? *shared_segments_ : segments_).get(delta.count());
    const double d = to_seconds(delta);
    // q = [x − x_ref; u − u_ref]: mean and covariance block.
    Vector<double, kQ> mq;
    for (std::size_t i = 0; i < N; ++i) mq[i] = m_[i] - x_ref_[i];
    for (std::size_t j = 0; j < M; ++j) mq[N + j] = m_[N + j] - u_ref_[j];
    const Matrix<double, kQ, kQ> sq = s_.template block<0, 0, kQ, kQ>();
    double tr_g = 0;
    for (std::size_t i = 0; i < kQ; ++i)
      for (std::size_t j = 0; j < kQ; ++j) tr_g += seg.g(i, j) * sq(j, i);
    double u_mean = 0;
    double u_cov = 0;
    for (std::size_t i = 0; i < M; ++i)
      for (std::size_t j = 0; j < M; ++j) {
        u_mean += mq[N + i] * plant_.q2c(i, j) * mq[N + j];
        u_cov += plant_.q2c(i, j) * sq(N + j, N + i);
      }
    cost_.mean += quadratic_form(seg.g, mq) + u_mean * d;
    cost_.covariance += tr_g + u_cov * d;
    // x⁺ = x_ref + Φ e + Γ ũ (the plant's own order of operations); registers unchanged.
    const Vector<double, N> e = mq.template block<0, 0, N, 1>();
    const Vector<double, M> du = mq.template block<N, 0, M, 1>();
    const Vector<double, N> x1 = seg.phi * e + seg.gamma * du + x_ref_;
    for (std::size_t i = 0; i < N; ++i) m_[i] = x1[i];
    // Σ⁺ = T Σ Tᵀ: rows of x, then columns of x.
    Matrix<double, N, kQ> t;
    t.template set_block<0, 0>(seg.phi);
    t.template set_block<0, N>(seg.gamma);
    const Matrix<double, N, K> top = t * s_.template block<0, 0, kQ, K>();  // T_x Σ
    for (std::size_t i = 0; i < N; ++i)
      for (std::size_t j = 0; j < K; ++j) s_(i, j) = top(i, j);
    const Matrix<double, K, kQ> left = s_.template block<0, 0, K, kQ>();
    const Matrix<double, K, N> cols = left * t.transposed();  // (T Σ) T_xᵀ
    for (std::size_t i = 0; i < K; ++i)
      for (std::size_t j = 0; j < N; ++j) s_(i, j) = cols(i, j);
    if (noisy_) {
      ProcessNoise<N>& noise = shared_noise_ != nullptr ? *shared_noise_ : noise_;
      const Matrix<double, N, N>& qd = noise.interval_covariance(delta);
      for (std::size_t i = 0; i < N; ++i)
        for (std::size_t j = 0; j < N; ++j) s_(i, j) += qd(i, j);
      cost_.noise_path += noise.interval_cost(delta);
    }
    mirror_upper(s_);
  }

  /// Event jump z⁺ = E z + F v + g, v ~ N(0, R) independent of z.
  template <std::size_t V>
  void jump(const Map& e, const Matrix<double, K, V>& f, const Z& g, const Matrix<double, V, V>& r) {
    m_ = e * m_ + g;
    s_ = e * s_ * e.transposed() + f * r * f.transposed();
    mirror_upper(s_);
  }
  /// Event jump without noise: z⁺ = E z + g.
  void jump(const Map& e, const Z& g) {
    m_ = e * m_ + g;
    s_ = e * s_ * e.transposed();
    mirror_upper(s_);
  }

  /// A discrete cost term at an event (a discrete plant's per-step cost, a penalty per
  /// message): E[(z − c)ᵀ W (z − c)] = (m − c)ᵀ W (m − c) + tr(W Σ), added to the mean and
  /// covariance parts.
  void add_event_cost(const Map& w, const Z& c) {
    const Z d = m_ - c;
    double tr = 0;
    for (std::size_t i = 0; i < K; ++i)
      for (std::size_t j = 0; j < K; ++j) tr += w(i, j) * s_(j, i);
    cost_.mean += quadratic_form(w, d);
    cost_.covariance += tr;
  }

  const Z& mean() const { return m_; }              ///< m = E z now.
  const Cov& covariance() const { return s_; }      ///< Σ = Cov z now.
  const ExpectedCost& cost() const { return cost_; }  ///< Expected cost so far.

 private:
  JumpLinearPlant<N, M> plant_;
  ProcessNoise<N> noise_;
  ExactSegmentCache<N, M> segments_;
  ExactSegmentCache<N, M>* shared_segments_ = nullptr;
  ProcessNoise<N>* shared_noise_ = nullptr;
  bool noisy_ = false;
  Z m_{};
  Cov s_{};
  Vector<double, N> x_ref_{};
  Vector<double, M> u_ref_{};
  ExpectedCost cost_{};
};

}  // namespace oneshot::engine
