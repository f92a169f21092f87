/// @file held_measurement_estimator.hpp
/// @brief The estimator of send-on-delta nodes (send-on-delta brief §4): a Kalman filter
///        that runs every period and corrects with one scalar measurement per node.
///
///     x̂⁻ = A_d x̂ + B_d u,          P⁻ = A_d P A_dᵀ + Q_d                   (predict)
///     for each node i with a measurement (z_i, R̄_ii), in turn:
///         c = row i of C,  s = c P cᵀ + R̄_ii,  k = P cᵀ / s,
///         x̂ ← x̂ + k (z_i − c x̂),   P ← P − k (P cᵀ)ᵀ = (I − k c) P           (correct)
/// R̄ is diagonal, so the scalar corrections in sequence equal the joint correction with
/// K = P⁻Cᵀ(C P⁻Cᵀ + R̄)⁻¹ (the measurements' errors are independent); no matrix inverse,
/// one division per node. P is updated on its upper triangle and mirrored, so it stays
/// exactly symmetric. The estimate never stays non-finite: when x̂ or P turns NaN or ±∞
/// (a huge input or measurement) predict()/correct() reset them to the values of reset()
/// (the design's x0, P0) and return Status::kNonFinite.
#pragma once

#include <cstddef>

#include "oneshot/finite.hpp"
#include "oneshot/matrix.hpp"
#include "oneshot/scalar_traits.hpp"
#include "oneshot/status.hpp"

namespace oneshot::node {

/// Kalman filter with N states, M inputs and P scalar measurement channels (rows of C).
template <typename S, std::size_t N, std::size_t M, std::size_t P>
class HeldMeasurementEstimator {
  static_assert(kIsFloating<S>, "the estimator runs in a floating format");

 public:
  using StateVec = Vector<S, N>;
  using InputVec = Vector<S, M>;
  using Cov = Matrix<S, N, N>;

  /// Model per period: A_d, B_d, Q_d and the output matrix C.
  constexpr HeldMeasurementEstimator(const Cov& a_d, const Matrix<S, N, M>& b_d, const Cov& q_d,
                                     const Matrix<S, P, N>& c)
      : a_(a_d), b_(b_d), q_(q_d), c_(c) {}

  /// Estimate x0 with covariance p0 (also the values a non-finite result resets to).
  constexpr void reset(const StateVec& x0, const Cov& p0) {
    x0_ = x0;
    p0_ = p0;
    x_ = x0;
    p_ = p0;
  }

  /// x̂⁻ = A_d x̂ + B_d u,  P⁻ = A_d P A_dᵀ + Q_d; kNonFinite (reset) when they overflow.
  [[nodiscard]] constexpr Status predict(const InputVec& u) {
    StateVec x{};
    for (std::size_t i = 0; i < N; ++i) {
      S acc = ScalarTraits<S>::zero();
      for (std::size_t j = 0; j < N; ++j) acc += a_(i, j) * x_[j];
      for (std::size_t j = 0; j < M; ++j) acc += b_(i, j) * u[j];
      x[i] = acc;
    }
    x_ = x;
    Cov ap{};  // A_d P
    for (std::size_t i = 0; i < N; ++i)
      for (std::size_t j = 0; j < N; ++j) {
        S acc = ScalarTraits<S>::zero();
        for (std::size_t l = 0; l < N; ++l) acc += a_(i, l) * p_(l, j);
        ap(i, j) = acc;
      }
    for (std::size_t i = 0; i < N; ++i)
      for (std::size_t j = i; j < N; ++j) {
        S acc = q_(i, j);
        for (std::size_t l = 0; l < N; ++l) acc += ap(i, l) * a_(j, l);
        p_(i, j) = acc;
        p_(j, i) = acc;
      }
    return finite_or_reset();
  }

  /// Scalar correction with measurement `z` of output `i` and variance `r_bar` (R̄_ii):
  /// kSingular (nothing changed) when the innovation variance is not positive, kNonFinite
  /// (reset) when x̂ or P turned NaN or ±∞.
  [[nodiscard]] constexpr Status correct(std::size_t i, S z, S r_bar) {
    StateVec pc{};  // P cᵀ
    S cx = ScalarTraits<S>::zero();
    for (std::size_t a = 0; a < N; ++a) {
      S acc = ScalarTraits<S>::zero();
      for (std::size_t b = 0; b < N; ++b) acc += p_(a, b) * c_(i, b);
      pc[a] = acc;
      cx += c_(i, a) * x_[a];
    }
    S s = r_bar;
    for (std::size_t a = 0; a < N; ++a) s += c_(i, a) * pc[a];
    if (!(ScalarTraits<S>::zero() < s)) return is_finite(s) ? Status::kSingular : reset_non_finite();
    const S innovation = z - cx;
    for (std::size_t a = 0; a < N; ++a) {
      gain_[a] = pc[a] / s;
      x_[a] += gain_[a] * innovation;
    }
    for (std::size_t a = 0; a < N; ++a)
      for (std::size_t b = a; b < N; ++b) {
        p_(a, b) -= gain_[a] * pc[b];
        p_(b, a) = p_(a, b);
      }
    return finite_or_reset();
  }

  /// The corrected estimate x̂ (after the corrections of this step).
  constexpr const StateVec& estimate() const { return x_; }
  /// Its covariance P.
  constexpr const Cov& covariance() const { return p_; }
  /// The gain of the last scalar correction.
  constexpr const StateVec& gain() const { return gain_; }

 private:
  constexpr Status reset_non_finite() {
    x_ = x0_;
    p_ = p0_;
    return Status::kNonFinite;
  }
  constexpr Status finite_or_reset() { return all_finite(x_) && all_finite(p_) ? Status::kOk : reset_non_finite(); }

  Cov a_;
  Matrix<S, N, M> b_;
  Cov q_;
  Matrix<S, P, N> c_;
  StateVec x0_{};
  Cov p0_{};
  StateVec x_{};
  Cov p_{};
  StateVec gain_{};
};

}  // namespace oneshot::node
