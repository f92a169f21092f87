/// @file linear_solve.hpp
/// @brief Small dense linear systems by LU with partial pivoting.
#pragma once

#include <cstddef>

#include "oneshot/matrix.hpp"
#include "oneshot/status.hpp"

namespace oneshot {

/// Solves A·X = B in place of X (X = A⁻¹B). Returns kSingular when a pivot is zero or
/// below N·ε·‖A‖∞ (numerically singular); X is then unspecified.
template <typename S, std::size_t N, std::size_t K>
[[nodiscard]] constexpr Status solve(Matrix<S, N, N> a, const Matrix<S, N, K>& b, Matrix<S, N, K>& x) {
  using T = ScalarTraits<S>;
  static_assert(T::kIsFloating, "solve() is for floating formats (design and host checks)");
  S norm = T::zero();
  for (std::size_t i = 0; i < N; ++i) {
    S row = T::zero();
    for (std::size_t j = 0; j < N; ++j) row = row + T::abs(a(i, j));
    if (norm < row) norm = row;
  }
  const S tiny = norm * T::from_double(T::kEpsilon) * T::from_int(static_cast<int>(N));
  x = b;
  for (std::size_t col = 0; col < N; ++col) {
    std::size_t pivot = col;
    for (std::size_t r = col + 1; r < N; ++r)
      if (T::abs(a(pivot, col)) < T::abs(a(r, col))) pivot = r;
    if (!(tiny < T::abs(a(pivot, col)))) return Status::kSingular;
    if (pivot != col) {
      for (std::size_t j = 0; j < N; ++j) {
        const S t = a(col, j);
        a(col, j) = a(pivot, j);
        a(pivot, j) = t;
      }
      for (std::size_t j = 0; j < K; ++j) {
        const S t = x(col, j);
        x(col, j) = x(pivot, j);
        x(pivot, j) = t;
      }
    }
    for (std::size_t r = col + 1; r < N; ++r) {
      const S f = a(r, col) / a(col, col);
      for (std::size_t j = col; j < N; ++j) a(r, j) = a(r, j) - f * a(col, j);
      for (std::size_t j = 0; j < K; ++j) x(r, j) = x(r, j) - f * x(col, j);
    }
  }
  for (std::size_t i = N; i-- > 0;) {
    for (std::size_t j = 0; j < K; ++j) {
      S v = x(i, j);
      for (std::size_t c = i + 1; c < N; ++c) v = v - a(i, c) * x(c, j);
      x(i, j) = v / a(i, i);
    }
  }
  return Status::kOk;
}

/// A⁻¹ (kSingular when A is numerically singular).
template <typename S, std::size_t N>
[[nodiscard]] constexpr Status invert(const Matrix<S, N, N>& a, Matrix<S, N, N>& inverse) {
  return solve(a, Matrix<S, N, N>::identity(), inverse);
}

}  // namespace oneshot
