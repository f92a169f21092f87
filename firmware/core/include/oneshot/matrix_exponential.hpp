/// @file matrix_exponential.hpp
/// @brief e^M by scaling and squaring with a Taylor polynomial sized for the scalar.
///
/// M is scaled by 2^-s until ‖M‖₁·2^-s ≤ θ = 1/2, e^(M/2^s) is evaluated by the Taylor
/// polynomial of degree m = ScalarTraits<S>::kTaylorDegree in Horner form,
///     E = I + X(I + X/2 (I + X/3 (… (I + X/m)))),
/// whose truncation error θ^(m+1)/(m+1)! is below half an ulp of S, and E is squared s
/// times. Taylor rather than Padé: no linear solve (so fixed point works the same way),
/// and at θ = 1/2 the extra products are few for the small orders used here.
#pragma once

#include <cstddef>

#include "oneshot/matrix.hpp"
#include "oneshot/status.hpp"

namespace oneshot {

/// Maximum number of squarings; ‖M‖₁ above 2^(kMaxSquarings−1) is rejected.
inline constexpr int kMaxSquarings = 40;

namespace detail {
/// 1/k in S for k = 1 … kTaylorDegree, rounded at compile time: the Horner loop then
/// multiplies, with no run-time division (a soft-float or 64-bit division on small MCUs).
template <typename S>
struct TaylorReciprocals {
  S value[ScalarTraits<S>::kTaylorDegree + 1];  ///< value[k] = 1/k (value[0] unused).
  constexpr TaylorReciprocals() : value{} {
    for (int k = 1; k <= ScalarTraits<S>::kTaylorDegree; ++k) value[k] = ScalarTraits<S>::from_ratio(1, k);
  }
};
/// The reciprocals for S.
template <typename S>
inline constexpr TaylorReciprocals<S> kTaylorReciprocals{};
}  // namespace detail

/// ‖M‖₁ (largest absolute column sum).
template <typename S, std::size_t N>
constexpr S one_norm(const Matrix<S, N, N>& m) {
  using T = ScalarTraits<S>;
  S norm = T::zero();
  for (std::size_t j = 0; j < N; ++j) {
    S col = T::zero();
    for (std::size_t i = 0; i < N; ++i) col = col + T::abs(m(i, j));
    if (norm < col) norm = col;
  }
  return norm;
}

/// result = e^M. Returns kOutOfRange (result unspecified) when ‖M‖₁ needs more than
/// kMaxSquarings halvings.
template <typename S, std::size_t N>
[[nodiscard]] constexpr Status matrix_exponential(const Matrix<S, N, N>& m, Matrix<S, N, N>& result) {
  using T = ScalarTraits<S>;
  constexpr S half = T::from_ratio(1, 2);
  Matrix<S, N, N> x = m;
  S norm = one_norm(m);
  int squarings = 0;
  while (half < norm) {  // ‖M‖₁/2^s ≤ θ = 1/2
    if (++squarings > kMaxSquarings) return Status::kOutOfRange;
    norm = norm * half;
    x = x * half;
  }
  const Matrix<S, N, N> eye = Matrix<S, N, N>::identity();
  Matrix<S, N, N> e = eye;
  for (int k = T::kTaylorDegree; k >= 1; --k) {
    e = eye + (x * e) * detail::kTaylorReciprocals<S>.value[k];  // E ← I + X·E/k
  }
  for (int s = 0; s < squarings; ++s) e = e * e;
  result = e;
  return Status::kOk;
}

}  // namespace oneshot
