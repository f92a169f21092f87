/// @file numre_estimator.hpp
/// @brief Non-uniform multi-rate estimator (NUMRE, numre-petc.md §4): a Kalman filter that
///        runs only when a measurement arrives, N = k − k_prev periods after the previous one.
///
/// Between arrivals the node propagates one period at a time with the inputs actually
/// applied (the same result as tabulating A^N, and no table):
///     x̂ ← A x̂ + B u_j,   P ← A P Aᵀ + B_w W B_wᵀ          (j = k − N … k − 1)
/// so after N steps x̂ = x̂(k|k−N) and P = A^N P (A^N)ᵀ + W_e(N),
///     W_e(N) = Σ_{c=0}^{N−1} A^c B_w W B_wᵀ (A^c)ᵀ            (the brief's correction).
/// The printed eq. 13 (w frozen over the interval) is kept as a switch: P ← A P Aᵀ per step
/// and G ← A G + B_w, then M = P + G W Gᵀ with G = Σ A^c B_w.
/// On arrival (one output, p = 1), Joseph form:
///     S = C M Cᵀ + V,  K = M Cᵀ / S,  x̂ ← x̂ + K (y − C x̂),
///     P = (I − K C) M (I − K C)ᵀ + K V Kᵀ.
/// Multiply-adds are counted as executed (dense), for the study's cost figures.
/// The estimate never stays non-finite: a correction that leaves x̂ or P NaN or ±∞ resets
/// them to the initial values (reset(); x̂ = 0, P = 0 at construction) and reports
/// Status::kNonFinite.
#pragma once

#include <cstddef>
#include <cstdint>

#include "oneshot/finite.hpp"
#include "oneshot/matrix.hpp"
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

/// The NUMRE filter (single input, single output, one noise input).
template <typename S, std::size_t N>
class NumreEstimator {
 public:
  using State = Vector<S, N>;        ///< x̂.
  using Covariance = Matrix<S, N, N>;  ///< P.

  /// Filter on `model` (copied) with the noise accumulation `acc`; x̂ = 0, P = 0.
  constexpr NumreEstimator(const NumreModel<S, N>& model, NoiseAccumulation acc) : m_(model), acc_(acc) {
    for (std::size_t i = 0; i < N; ++i)
      for (std::size_t j = 0; j < N; ++j) q_(i, j) = m_.b_w[i] * m_.w * m_.b_w[j];
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

  /// One period of open-loop prediction with the applied input u.
  constexpr void predict(S u) {
    x_ = m_.a * x_ + m_.b * u;
    p_ = (m_.a * p_) * m_.a.transposed();
    if (acc_ == NoiseAccumulation::kSum) {
      p_ = p_ + q_;
    } else {
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
    const State mct = p_ * m_.c.transposed();
    S s = m_.v;
    for (std::size_t i = 0; i < N; ++i) s = s + m_.c[i] * mct[i];
    macs_ += N * N + N;
    last_multiplicity_ = steps_;
    steps_ = 0;
    if (!(s > S(0))) {
      k_ = State{};
      return is_finite(s) ? Status::kSingular : reset_non_finite();
    }
    k_ = mct * (S(1) / s);
    S innovation = y;
    for (std::size_t i = 0; i < N; ++i) innovation = innovation - m_.c[i] * x_[i];
    x_ = x_ + k_ * innovation;
    Covariance ikc = Covariance::identity() - k_ * m_.c;
    p_ = (ikc * p_) * ikc.transposed();
    for (std::size_t i = 0; i < N; ++i)
      for (std::size_t j = 0; j < N; ++j) p_(i, j) = p_(i, j) + k_[i] * m_.v * k_[j];
    macs_ += 3 * N + N * N + 2 * N * N * N + 2 * N * N;
    return all_finite(x_) && all_finite(p_) ? Status::kOk : reset_non_finite();
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
  constexpr Status reset_non_finite() {
    x_ = x0_;
    p_ = p0_;
    g_ = State{};
    k_ = State{};
    return Status::kNonFinite;
  }

  NumreModel<S, N> m_;
  NoiseAccumulation acc_;
  Covariance q_{};
  State x0_{};
  Covariance p0_{};
  State x_{};
  Covariance p_{};
  State g_{};
  State k_{};
  std::uint32_t steps_ = 0;
  std::uint32_t last_multiplicity_ = 0;
  std::uint64_t macs_ = 0;
};

}  // namespace oneshot::node
