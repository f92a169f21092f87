/// @file compact_exponential.hpp
/// @brief e^V of a block upper-triangular Van Loan generator V = [[V11, V12], [0, V22]] whose
///        size k ≤ K is known at run time only, with the operations of matrix_exponential().
///
/// A plant embedded (zero padded) in a larger shape has Van Loan generators whose padded
/// indices are decoupled (their rows and columns zero); the exponential of the generator is then
/// the exponential of its coupled part, with 1 on the diagonal and 0 elsewhere at the decoupled
/// indices. ExactSegmentCache computes it on the coupled indices only, here: scaling while
/// ‖V‖₁ > 1/2, the Taylor polynomial in Horner form E ← I + (X E)·(1/j), E squared s times,
/// every product summed in the order of Matrix's operator* (acc = a₀b₀, then acc + aₗbₗ).
/// The products keep V's block triangle: a block product (A B)ᵢⱼ = Σₗ Aᵢₗ Bₗⱼ leaves out the
/// terms with a factor in the zero block, exact zeros, which can change no nonzero sum (only
/// the sign of an exact zero); the lower-left block is +0. ExactSegmentCache's tests compare
/// the resulting maps with the dense exponential to the byte.
#pragma once

#include <array>
#include <cmath>
#include <cstddef>

#include "oneshot/matrix_exponential.hpp"
#include "oneshot/status.hpp"

namespace oneshot::engine {

namespace detail {
/// out = a·b for k×k row-major block upper-triangular matrices (blocks of k/2; Matrix's
/// operator* order, no reassociation): (a b)ᵢⱼ = Σₗ aᵢₗ bₗⱼ over the l where neither factor is in
/// the zero lower-left block (the upper-left block: l < k/2; the lower-right: l ≥ k/2).
inline void compact_product(const double* a, const double* b, double* out, std::size_t k) {
  const std::size_t h = k / 2;
  for (std::size_t i = 0; i < k; ++i)
    for (std::size_t j = 0; j < k; ++j) {
      if (i >= h && j < h) {  // the lower-left block stays 0
        out[i * k + j] = 0.0;
        continue;
      }
      const std::size_t l0 = i >= h ? h : 0;
      const std::size_t l1 = j < h ? h : k;
      double acc = a[i * k + l0] * b[l0 * k + j];
      for (std::size_t l = l0 + 1; l < l1; ++l) acc = acc + a[i * k + l] * b[l * k + j];
      out[i * k + j] = acc;
    }
}
}  // namespace detail

/// out = e^M for the k×k row-major block upper-triangular `m` (k ≤ K even, blocks of k/2, the
/// lower-left one 0): matrix_exponential() of a Matrix<double, k, k> but for the zero terms left
/// out; kOutOfRange (out unspecified) when ‖M‖₁ needs more than kMaxSquarings halvings.
template <std::size_t K>
[[nodiscard]] Status compact_exponential(const double* m, std::size_t k, double* out) {
  std::array<double, K * K> x{};
  std::array<double, K * K> e{};
  std::array<double, K * K> t{};
  const std::size_t kk = k * k;
  double norm = 0;  // ‖M‖₁, the largest absolute column sum
  for (std::size_t j = 0; j < k; ++j) {
    double col = 0;
    for (std::size_t i = 0; i < k; ++i) col = col + std::fabs(m[i * k + j]);
    if (norm < col) norm = col;
  }
  for (std::size_t i = 0; i < kk; ++i) x[i] = m[i];
  int squarings = 0;
  while (0.5 < norm) {  // ‖M‖₁/2^s ≤ θ = 1/2
    if (++squarings > kMaxSquarings) return Status::kOutOfRange;
    norm = norm * 0.5;
    for (std::size_t i = 0; i < kk; ++i) x[i] = x[i] * 0.5;
  }
  for (std::size_t i = 0; i < kk; ++i) e[i] = i % (k + 1) == 0 ? 1.0 : 0.0;
  for (int j = ScalarTraits<double>::kTaylorDegree; j >= 1; --j) {  // E ← I + X·E/j
    detail::compact_product(x.data(), e.data(), t.data(), k);
    const double r = oneshot::detail::kTaylorReciprocals<double>.value[j];
    for (std::size_t i = 0; i < kk; ++i) e[i] = (i % (k + 1) == 0 ? 1.0 : 0.0) + t[i] * r;
  }
  for (int s = 0; s < squarings; ++s) {
    detail::compact_product(e.data(), e.data(), t.data(), k);
    e = t;
  }
  for (std::size_t i = 0; i < kk; ++i) out[i] = e[i];
  return Status::kOk;
}

}  // namespace oneshot::engine
