/// @file pattern.hpp
/// @brief Compile-time sparsity pattern: which entries are structurally 0 or 1.
///
/// A pattern describes a matrix-valued function (e.g. Φ(t) for every t), not one value:
/// an entry marked zero/one is exactly 0/1 for every argument, so kernels skip it at no
/// cost and the look-up table does not store it. The build-time generator derives the
/// patterns from the plant's graph structure (lut_gen), never from rounded numbers.
#pragma once

#include <cstddef>
#include <cstdint>

namespace oneshot {

/// R×C pattern; bit (i*C + j) of ZeroMask / OneMask marks entry (i, j).
template <std::size_t R, std::size_t C, std::uint64_t ZeroMask = 0, std::uint64_t OneMask = 0>
struct Pattern {
  static_assert(R * C <= 64, "patterns cover matrices of at most 64 entries");
  static_assert((ZeroMask & OneMask) == 0, "an entry cannot be both zero and one");
  static constexpr std::size_t kRows = R;          ///< Rows.
  static constexpr std::size_t kCols = C;          ///< Columns.
  static constexpr std::uint64_t kZeroMask = ZeroMask;  ///< Structural zeros.
  static constexpr std::uint64_t kOneMask = OneMask;    ///< Structural ones.

  /// Entry (i, j) is exactly zero for every argument.
  static constexpr bool is_zero(std::size_t i, std::size_t j) {
    return ((ZeroMask >> (i * C + j)) & 1U) != 0U;
  }
  /// Entry (i, j) is exactly one for every argument.
  static constexpr bool is_one(std::size_t i, std::size_t j) {
    return ((OneMask >> (i * C + j)) & 1U) != 0U;
  }
  /// Entry (i, j) carries data.
  static constexpr bool is_free(std::size_t i, std::size_t j) {
    return !is_zero(i, j) && !is_one(i, j);
  }
};

/// A pattern with no structural entries.
template <std::size_t R, std::size_t C>
using Dense = Pattern<R, C, 0, 0>;

namespace detail {
constexpr std::uint64_t transpose_mask(std::uint64_t mask, std::size_t r, std::size_t c) {
  std::uint64_t out = 0;
  for (std::size_t i = 0; i < r; ++i)
    for (std::size_t j = 0; j < c; ++j)
      if (((mask >> (i * c + j)) & 1U) != 0U) out |= std::uint64_t{1} << (j * r + i);
  return out;
}
}  // namespace detail

/// Pattern of the transpose.
template <typename P>
using Transposed = Pattern<P::kCols, P::kRows, detail::transpose_mask(P::kZeroMask, P::kRows, P::kCols),
                           detail::transpose_mask(P::kOneMask, P::kRows, P::kCols)>;

}  // namespace oneshot
