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
/// exactly symmetric. These are the core's KalmanEstimator operations (kalman_estimator.hpp:
/// predict() with the per-period triple (A_d, B_d, Q_d), correct() with output i alone
/// present, symmetric form); this class adds only the model it holds, the one-output call
/// and the non-finite reset. The estimate never stays non-finite: when x̂ or P turns NaN or ±∞
/// (a huge input or measurement) predict()/correct() reset them to the values of reset()
/// (the design's x0, P0) and return Status::kNonFinite.
#pragma once

#include <cstddef>
#include <cstdint>

#include "oneshot/finite.hpp"
#include "oneshot/kalman_estimator.hpp"
#include "oneshot/matrix.hpp"
#include "oneshot/number_format.hpp"
#include "oneshot/plant_structure.hpp"
#include "oneshot/scalar_traits.hpp"
#include "oneshot/status.hpp"

namespace oneshot::node {

/// Kalman filter with N states, M inputs and P scalar measurement channels (rows of C).
template <typename S, std::size_t N, std::size_t M, std::size_t P>
class HeldMeasurementEstimator {
  static_assert(kIsFloating<S>, "the estimator runs in a floating format");
  using Fmt = UniformFormat<S>;
  using Core = KalmanEstimator<Fmt, DenseStructure<N, M, P>, CovarianceUpdate::kSymmetric>;

 public:
  using StateVec = Vector<S, N>;  ///< x̂.
  using InputVec = Vector<S, M>;  ///< u.
  using Cov = Matrix<S, N, N>;    ///< P.

  /// Model per period: A_d, B_d, Q_d and the output matrix C.
  constexpr HeldMeasurementEstimator(const Cov& a_d, const Matrix<S, N, M>& b_d, const Cov& q_d,
                                     const Matrix<S, P, N>& c)
      : c_(c) {
    step_.phi = a_d;
    step_.gamma = b_d;
    step_.qd = q_d;
  }

  /// Estimate x0 with covariance p0 (also the values a non-finite result resets to).
  constexpr void reset(const StateVec& x0, const Cov& p0) {
    x0_ = x0;
    p0_ = p0;
    core_.reset(x0, p0);
  }

  /// x̂⁻ = A_d x̂ + B_d u,  P⁻ = A_d P A_dᵀ + Q_d; kNonFinite (reset) when they overflow.
  [[nodiscard]] constexpr Status predict(const InputVec& u) {
    core_.predict(step_, u, NoiseModel::kExact, step_.qd);
    return finite_or_reset();
  }

  /// Scalar correction with measurement `z` of output `i` and variance `r_bar` (R̄_ii):
  /// kSingular (nothing changed) when the innovation variance is not positive, kNonFinite
  /// (reset) when it, x̂ or P turned NaN or ±∞.
  [[nodiscard]] constexpr Status correct(std::size_t i, S z, S r_bar) {
    Vector<S, P> y;
    Vector<S, P> r;
    y[i] = z;
    r[i] = r_bar;
    last_ = i;
    const Status s = core_.correct(y, static_cast<OutputMask>(1U << i), r, c_);
    // A NaN r̄ makes the innovation variance NaN: the core skips the update (kSingular).
    if (s == Status::kSingular && !is_finite(r_bar)) return reset_non_finite();
    return worst_of(s, finite_or_reset());
  }

  /// The corrected estimate x̂ (after the corrections of this step).
  constexpr const StateVec& estimate() const { return core_.state(); }
  /// Its covariance P.
  constexpr const Cov& covariance() const { return core_.covariance(); }
  /// The gain of the last scalar correction.
  constexpr StateVec gain() const {
    StateVec k;
    for (std::size_t a = 0; a < N; ++a) k[a] = core_.gain()(a, last_);
    return k;
  }

 private:
  [[nodiscard]] constexpr Status reset_non_finite() {
    core_.reset(x0_, p0_);
    return Status::kNonFinite;
  }
  [[nodiscard]] constexpr Status finite_or_reset() {
    return all_finite(core_.state()) && all_finite(core_.covariance()) ? Status::kOk : reset_non_finite();
  }

  Discretization<Fmt, N, M> step_{};  ///< (A_d, B_d, Q_d): one period.
  Matrix<S, P, N> c_;
  StateVec x0_{};
  Cov p0_{};
  Core core_{};
  std::size_t last_ = 0;
};

}  // namespace oneshot::node
