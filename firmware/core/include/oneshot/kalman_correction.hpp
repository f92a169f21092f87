/// @file kalman_correction.hpp
/// @brief Measurement update of a Kalman filter, shared by every variant.
///
///   S = C P⁻ Cᵀ + R,  K = P⁻ Cᵀ S⁻¹,  x̂ = x̂⁻ + K (y − C x̂⁻),
///   symmetric form:  P = P⁻ − K (P⁻Cᵀ)ᵀ        (upper triangle, mirrored)
///   Joseph form:     P = (I − K C) P⁻ (I − K C)ᵀ + K R Kᵀ
/// The symmetric form is the default: it is exactly symmetric by construction and,
/// for the optimal gain, tests/firmware/kalman_filters_test.cpp shows it stays positive
/// definite and within 10⁻³ relative of double over 10⁶ float32 steps, at about half
/// the operations of Joseph (which remains selectable).
#pragma once

#include <cstddef>

#include "oneshot/innovation.hpp"
#include "oneshot/linear_solve.hpp"
#include "oneshot/matrix.hpp"
#include "oneshot/status.hpp"
#include "oneshot/structured_ops.hpp"

namespace oneshot {

/// Form of the covariance measurement update.
enum class CovarianceUpdate : std::uint8_t { kSymmetric, kJoseph };

/// Updates x, P with measurement y; writes the gain used to k. kSingular (x, P
/// untouched) when the innovation variance is not positive.
template <typename Fmt, typename Structure, CovarianceUpdate kForm, std::size_t N, std::size_t P>
[[nodiscard]] constexpr Status correct(Vector<typename Fmt::State, N>& x, Matrix<typename Fmt::Covariance, N, N>& p,
                         const Vector<typename Fmt::State, P>& y,
                         const Matrix<typename Fmt::Transition, P, N>& c,
                         const Matrix<typename Fmt::Covariance, P, P>& r,
                         Matrix<typename Fmt::KalmanGain, N, P>& k) {
  using Cov = typename Fmt::Covariance;
  using Gain = typename Fmt::KalmanGain;
  using CP = typename Structure::OutputPattern;
  // P⁻Cᵀ (n×p) and S = C (P⁻Cᵀ) + R.
  const Matrix<Cov, N, P> pct = product<Cov, Dense<N, N>, Transposed<CP>>(p, c.transposed());
  Matrix<Cov, P, P> s = product<Cov, CP, Dense<N, P>>(c, pct);
  for (std::size_t i = 0; i < P; ++i)
    for (std::size_t j = 0; j < P; ++j) s(i, j) = s(i, j) + r(i, j);
  if constexpr (P == 1) {
    if (!(ScalarTraits<Cov>::zero() < s(0, 0))) return Status::kSingular;
    const auto inv_s = reciprocal<typename Fmt::InverseCovariance>(s(0, 0));  // K = P⁻Cᵀ·S⁻¹
    for (std::size_t i = 0; i < N; ++i) k(i, 0) = mul<Gain>(pct(i, 0), inv_s);
  } else {
    static_assert(kIsFloating<Cov>, "several outputs need a floating format");
    Matrix<Cov, P, N> kt;
    const Status st = solve(s, pct.transposed(), kt);  // S Kᵀ = (P⁻Cᵀ)ᵀ
    if (st != Status::kOk) return st;
    k = convert_matrix<Gain>(kt.transposed());
  }
  add_gain_times<Fmt>(x, k, innovation<Fmt, CP>(y, c, x));
  if constexpr (kForm == CovarianceUpdate::kSymmetric) {
    fill_symmetric(p, [&](std::size_t i, std::size_t j) __attribute__((always_inline)) {  // P = P⁻ − K (P⁻Cᵀ)ᵀ
      Accumulator<Cov> acc;
      acc.add(p(i, j));
      for (std::size_t o = 0; o < P; ++o) acc.sub_product(k(i, o), pct(j, o));
      return acc.value();
    });
  } else {
    // A = I − K C, P = A P Aᵀ + K R Kᵀ.
    Matrix<Gain, N, N> a = product<Gain, Dense<N, P>, CP>(k, c);
    for (std::size_t i = 0; i < N; ++i)
      for (std::size_t j = 0; j < N; ++j)
        a(i, j) = i == j ? ScalarTraits<Gain>::one() - a(i, j) : -a(i, j);
    const Matrix<Cov, N, N> apa = congruence<Cov, Dense<N, N>>(a, p);
    const Matrix<Cov, N, P> kr = product<Cov, Dense<N, P>, Dense<P, P>>(k, r);
    fill_symmetric(p, [&](std::size_t i, std::size_t j) __attribute__((always_inline)) {  // A P Aᵀ + (K R) Kᵀ
      Accumulator<Cov> acc;
      acc.add(apa(i, j));
      for (std::size_t o = 0; o < P; ++o) acc.add_product(kr(i, o), k(j, o));
      return acc.value();
    });
  }
  return Status::kOk;
}

}  // namespace oneshot
