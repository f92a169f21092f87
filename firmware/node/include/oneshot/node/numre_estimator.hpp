/// @file numre_estimator.hpp
/// @brief Non-uniform multi-rate estimator (NUMRE, numre-petc.md §4): a Kalman filter that
///        runs only when a measurement arrives, N = k − k_prev periods after the previous one.
///
/// predict(u) propagates one period at a time with the inputs actually applied (the
/// step-by-step form, kept as the reference the tests compare with):
///     x̂ ← A x̂ + B u_j,   P ← A P Aᵀ + B_w W B_wᵀ          (j = k − N … k − 1)
/// so after N steps x̂ = x̂(k|k−N) and P = A^N P (A^N)ᵀ + W_e(N),
///     W_e(N) = Σ_{c=0}^{N−1} A^c B_w W B_wᵀ (A^c)ᵀ            (the brief's correction).
/// The printed eq. 13 (w frozen over the interval) is kept as a switch: P ← A P Aᵀ per step
/// and G ← A G + B_w, then M = P + G W Gᵀ with G = Σ A^c B_w.
/// predict_along(N, …) does the same N periods at once from the span table (numre_span_table.hpp,
/// A^j and W_e(j) for j = d·15^p): P ← A^j P (A^j)ᵀ + W_e(j) for each base-15 digit of N (at
/// most 2 for N < 225), and x̂ from a model trajectory x_r under the same applied inputs:
///     x̂(k|k−N) = x_r(k) + A^N (x̂(k−N|k−N) − x_r(k−N))
/// (the inputs cancel in the difference), so its cost does not grow with N.
/// On arrival (one output, p = 1), Joseph form expanded for the scalar output (O(n²), exact
/// for any gain K):
///     m = M Cᵀ,  S = C m + V,  K = m / S,  x̂ ← x̂ + K (y − C x̂),
///     P = (I − K C) M (I − K C)ᵀ + K V Kᵀ = M − K mᵀ − m Kᵀ + S K Kᵀ.
/// Multiply-adds are counted as executed (exact zeros of A^j and C skipped), for the
/// study's cost figures.
/// The estimate never stays non-finite: a correction that leaves x̂ or P NaN or ±∞ resets
/// them to the initial values (reset(); x̂ = 0, P = 0 at construction) and reports
/// Status::kNonFinite.
///
/// Why the arrival path is not the core's KalmanEstimator (kalman_estimator.hpp): the step-by-
/// step predict(u) is the same maths and runs on it; the arrival (predict_along + correct) is
/// the same filter computed differently, for the Cortex-M4F budget (≤ 60,000 instructions
/// per arrival, bit-identical host float vs M4F):
///  * the N-period prediction uses the span table (A^j, W_e(j) for j = d·15^p) and the model
///    trajectory x_r, so its cost does not grow with N; the core predicts one interval (or
///    N steps, N times the cost: 1,799,895 instructions at N = 97 when measured step by step);
///  * every product is unrolled over the compile-time nonzeros of A's closure and of C
///    (numre_structure.hpp: 32 nonzeros in the block-diagonal basis of the study), where the
///    core's patterns are per-matrix and its loops run-time;
///  * the correction is the Joseph form expanded for one output, P = M − K mᵀ − m Kᵀ + S K Kᵀ
///    over C's nonzeros, O(n²); the core's Joseph correction forms (I − K C) M (I − K C)ᵀ,
///    O(n³), and its symmetric form P − K mᵀ is exact only for the optimal gain;
///  * finiteness is one sum of the new values instead of a test per entry.
/// Its results equal the step-by-step core prediction and the Eigen Joseph oracle within
/// rounding (tests/sim_host/petc/numre_test.cpp, numre_span_test.cpp).
#pragma once

#include <cstddef>
#include <cstdint>

#include "oneshot/finite.hpp"
#include "oneshot/kalman_estimator.hpp"
#include "oneshot/matrix.hpp"
#include "oneshot/number_format.hpp"
#include "oneshot/plant_structure.hpp"
#include "oneshot/node/numre_span_table.hpp"
#include "oneshot/node/numre_structure.hpp"
#include "oneshot/status.hpp"

namespace oneshot::node {

/// Model of a NUMRE: x⁺ = A x + B u + B_w w, y = C x + v, d̂ = C̄ x; W = var w, V = var v.
template <typename S, std::size_t N>
struct NumreModel {
  Matrix<S, N, N> a;        ///< A (one period T).
  Vector<S, N> b;           ///< B.
  Vector<S, N> b_w;         ///< B_w.
  Matrix<S, 1, N> c;        ///< C.
  Matrix<S, 1, N> c_bar;    ///< C̄: the input disturbance the model estimates (zero row: none).
  S w = S(0);               ///< W: variance of w per period.
  S v = S(0);               ///< V: variance of the measurement noise.
};

/// How the process noise of N silent periods is accumulated.
enum class NoiseAccumulation : std::uint8_t {
  kSum,     ///< W_e(N) = Σ A^c B_w W B_wᵀ (A^c)ᵀ (exact for white w).
  kFrozen,  ///< Printed eq. 13: (Σ A^c B_w) W (Σ A^c B_w)ᵀ (w held over the interval).
};

/// Q = B_w W B_wᵀ of a model.
template <typename S, std::size_t N>
constexpr Matrix<S, N, N> numre_process_noise(const NumreModel<S, N>& m) {
  Matrix<S, N, N> q;
  for (std::size_t i = 0; i < N; ++i)
    for (std::size_t j = 0; j < N; ++j) q(i, j) = m.b_w[i] * m.w * m.b_w[j];
  return q;
}

/// The NUMRE filter (single input, single output, one noise input) on a model that fits
/// `Structure` (numre_structure.hpp; the default assumes nothing).
template <typename S, std::size_t N, typename Structure = DenseModelStructure<N>>
class NumreEstimator {
 public:
  using State = Vector<S, N>;        ///< x̂.
  using Covariance = Matrix<S, N, N>;  ///< P.
  using Spans = NumreSpanTable<S, N, 15, 2>;  ///< j = d·15^p: N < 225 in at most 2 spans.
  using Powers = ClosureStructure<Structure, N>;  ///< Where A^j may be nonzero.

  /// True when `model` fits Structure (the filter must not be used otherwise).
  static constexpr bool fits(const NumreModel<S, N>& model) {
    return fits_structure<Structure>(model.a, model.b, model.c, model.c_bar);
  }

  /// Filter on `model` (copied) with the noise accumulation `acc`; x̂ = 0, P = 0.
  constexpr NumreEstimator(const NumreModel<S, N>& model, NoiseAccumulation acc)
      : m_(model), acc_(acc), q_(numre_process_noise(model)), spans_(m_.a, m_.b, m_.b_w, q_) {}

  /// N periods at once from the span table: x̂ ← x_r(k) + A^N (x̂ − x_r(k − N)) for a model
  /// trajectory x_r under the applied inputs (`ref_then` at k − N, `ref_now` at k), and
  /// P ← A^N P (A^N)ᵀ + W_e(N) (kFrozen: P ← A^N P (A^N)ᵀ, G ← A^N G + G(N)).
  constexpr void predict_along(std::uint32_t n, const State& ref_then, const State& ref_now) {
    State d = x_ - ref_then;
    spans_.for_each_span(n, [&](const typename Spans::Span& sp) {
      State t;
      macs_ += masked_product<Powers>(sp.a, d, t);
      d = t;
      macs_ += masked_sandwich<Powers>(sp.a, p_);
      if (acc_ == NoiseAccumulation::kSum) {
        std::size_t q = 0;
        for (std::size_t i = 0; i < N; ++i)
          for (std::size_t c = i; c < N; ++c) {
            const S v = p_(i, c) + sp.w[q++];
            p_(i, c) = v;
            p_(c, i) = v;
          }
      } else {
        macs_ += masked_product<Powers>(sp.a, g_, t);
        g_ = t + sp.g;
      }
    });
    x_ = ref_now + d;
    steps_ += n;
  }

  /// x ← A^n x + Γ(n) u: the model n periods on with u held (span table).
  constexpr void advance(std::uint32_t n, State& x, S u) {
    spans_.for_each_span(n, [&](const typename Spans::Span& sp) {
      State t;
      macs_ += masked_product<Powers>(sp.a, x, t) + N;
      x = t + sp.gamma * u;
    });
  }

  /// Sets x̂ and P (the last arrival's values; also what a non-finite result resets to).
  constexpr void reset(const State& x, const Covariance& p) {
    x0_ = x;
    p0_ = p;
    x_ = x;
    p_ = p;
    g_ = State{};
    steps_ = 0;
  }

  /// One period of open-loop prediction with the applied input u: the core's predict with
  /// Φ = A, Γ = B and Q = B_w W B_wᵀ (kSum) or no Q and G ← A G + B_w (kFrozen). The reference
  /// the arrival path is tested against (not used on the node).
  constexpr void predict(S u) {
    using Core = KalmanEstimator<UniformFormat<S>, DenseStructure<N, 1, 1>>;
    typename Core::Triple step;
    step.phi = m_.a;
    for (std::size_t i = 0; i < N; ++i) step.gamma(i, 0) = m_.b[i];
    if (acc_ == NoiseAccumulation::kSum) step.qd = q_;
    typename Core::InputVec uv;
    uv[0] = u;
    Core core;
    core.reset(x_, p_);
    core.predict(step, uv, NoiseModel::kExact, step.qd);
    x_ = core.state();
    p_ = core.covariance();
    if (acc_ == NoiseAccumulation::kFrozen) {
      g_ = m_.a * g_ + m_.b_w;
      macs_ += N * N;
    }
    macs_ += N * N + N + 2 * N * N * N;
    ++steps_;
  }

  /// Arrival of y after `multiplicity()` predictions: finishes M_k and corrects (Joseph).
  /// kSingular (x̂, P untouched apart from M_k) when C M Cᵀ + V is not positive; kNonFinite
  /// when x̂ or P turned NaN or ±∞ (reset to the initial values); kOk otherwise.
  [[nodiscard]] constexpr Status correct(S y) {
    if (acc_ == NoiseAccumulation::kFrozen) {
      for (std::size_t i = 0; i < N; ++i)
        for (std::size_t j = 0; j < N; ++j) p_(i, j) = p_(i, j) + g_[i] * m_.w * g_[j];
      macs_ += N * N;
      g_ = State{};
    }
    State mct;  // m = M Cᵀ over C's nonzeros
    Unrolled<0, N>::run([&](auto ic) {
      constexpr std::size_t i = decltype(ic)::value;
      mct[i] = masked_dot<Structure::kC>(m_.c, row_of(p_, i));
    });
    const S s = m_.v + masked_dot<Structure::kC>(m_.c, mct);
    macs_ += (N + 1) * mask_count(Structure::kC);
    last_multiplicity_ = steps_;
    steps_ = 0;
    if (!(s > S(0))) {
      k_ = State{};
      return is_finite(s) ? Status::kSingular : reset_non_finite();
    }
    k_ = mct * (S(1) / s);
    const S innovation = y - masked_dot<Structure::kC>(m_.c, x_);
    x_ = x_ + k_ * innovation;
    // Joseph form expanded: P = M − K mᵀ − m Kᵀ + S K Kᵀ (upper triangle, mirrored).
    // Finiteness: the sum of the new values is non-finite when any is (NaN and ±∞ are
    // absorbing under +; ∞ − ∞ = NaN), one addition per value instead of a bit test; it
    // also resets if the sum alone overflows (|entries| near the largest finite value).
    S sum = innovation;
    for (std::size_t i = 0; i < N; ++i)
      for (std::size_t j = i; j < N; ++j) {
        const S v = p_(i, j) - k_[i] * mct[j] - mct[i] * k_[j] + s * k_[i] * k_[j];
        p_(i, j) = v;
        p_(j, i) = v;
        sum = sum + v;
      }
    for (std::size_t i = 0; i < N; ++i) sum = sum + x_[i];
    macs_ += 2 * N + mask_count(Structure::kC) + 4 * (N * (N + 1) / 2);
    return is_finite(sum) ? Status::kOk : reset_non_finite();
  }

  /// x̂ (x̂(k|k) after correct(), the prediction before).
  constexpr const State& state() const { return x_; }
  /// P (or M_k before correct()).
  constexpr const Covariance& covariance() const { return p_; }
  /// K(N) of the last correction.
  constexpr const State& gain() const { return k_; }
  /// N of the last correction (periods predicted before it).
  constexpr std::uint32_t last_multiplicity() const { return last_multiplicity_; }
  /// The model.
  constexpr const NumreModel<S, N>& model() const { return m_; }
  /// Multiply-adds executed so far.
  constexpr std::uint64_t macs() const { return macs_; }

 private:
  [[nodiscard]] constexpr Status reset_non_finite() {
    x_ = x0_;
    p_ = p0_;
    g_ = State{};
    k_ = State{};
    return Status::kNonFinite;
  }

  NumreModel<S, N> m_;
  NoiseAccumulation acc_;
  Covariance q_{};
  Spans spans_;
  State x0_{};
  Covariance p0_{};

  /// Row i of P as a vector.
  static constexpr State row_of(const Covariance& p, std::size_t i) {
    State r;
    for (std::size_t j = 0; j < N; ++j) r[j] = p(i, j);
    return r;
  }
  State x_{};
  Covariance p_{};
  State g_{};
  State k_{};
  std::uint32_t steps_ = 0;
  std::uint32_t last_multiplicity_ = 0;
  std::uint64_t macs_ = 0;
};

}  // namespace oneshot::node
