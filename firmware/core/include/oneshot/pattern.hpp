/// @file pattern.hpp
/// @brief Compile-time sparsity pattern: which entries are structurally 0 or 1.
///
/// A pattern describes a matrix-valued function (e.g. Φ(t) for every t), not one value:
/// an entry marked zero/one is exactly 0/1 for every argument, so kernels skip it at no
/// cost and the look-up table does not store it. The build-time generator derives the
/// patterns from the plant's graph structure (lut_gen), never from rounded numbers.
///
/// Entry (i, j) is bit b = i·C + j, held in 64-bit word b / 64 (up to four words: 256
/// entries, a kMaxStates × kMaxStates Φ). The template arguments interleave the words of
/// the two masks, Pattern<R, C, Zero₀, One₀, Zero₁, One₁, …>, so the one-word spelling
/// Pattern<R, C, Zero, One> of small matrices is unchanged.
#pragma once

#include <cstddef>
#include <cstdint>

#include "oneshot/dimension_limits.hpp"

namespace oneshot {

/// Entries a pattern can describe (four 64-bit words per mask).
inline constexpr std::size_t kMaxPatternEntries = 256;
static_assert(kMaxStates * kMaxStates <= kMaxPatternEntries, "a kMaxStates x kMaxStates pattern must fit the masks");

namespace detail {
constexpr bool bit_of(std::uint64_t w0, std::uint64_t w1, std::uint64_t w2, std::uint64_t w3, std::size_t b) {
  const std::uint64_t w = b < 64 ? w0 : b < 128 ? w1 : b < 192 ? w2 : w3;
  return ((w >> (b % 64)) & 1U) != 0U;
}
/// True when no bit at or beyond `entries` is set.
constexpr bool bits_within(std::uint64_t w0, std::uint64_t w1, std::uint64_t w2, std::uint64_t w3,
                           std::size_t entries) {
  for (std::size_t b = entries; b < kMaxPatternEntries; ++b)
    if (bit_of(w0, w1, w2, w3, b)) return false;
  return true;
}
}  // namespace detail

/// R×C pattern; bit (i*C + j) of the zero / one masks marks entry (i, j).
template <std::size_t R, std::size_t C, std::uint64_t Zero0 = 0, std::uint64_t One0 = 0, std::uint64_t Zero1 = 0,
          std::uint64_t One1 = 0, std::uint64_t Zero2 = 0, std::uint64_t One2 = 0, std::uint64_t Zero3 = 0,
          std::uint64_t One3 = 0>
struct Pattern {
  static_assert(R * C <= kMaxPatternEntries,
                "patterns cover matrices of at most kMaxPatternEntries (256) entries: kMaxStates x kMaxStates");
  static_assert((Zero0 & One0) == 0 && (Zero1 & One1) == 0 && (Zero2 & One2) == 0 && (Zero3 & One3) == 0,
                "an entry cannot be both zero and one");
  static_assert(detail::bits_within(Zero0, Zero1, Zero2, Zero3, R * C) &&
                    detail::bits_within(One0, One1, One2, One3, R * C),
                "a mask marks an entry outside the R x C matrix");
  static constexpr std::size_t kRows = R;          ///< Rows.
  static constexpr std::size_t kCols = C;          ///< Columns.
  static constexpr std::uint64_t kZeroMask = Zero0;  ///< Structural zeros of entries 0 … 63.
  static constexpr std::uint64_t kOneMask = One0;    ///< Structural ones of entries 0 … 63.

  /// Entry (i, j) is exactly zero for every argument.
  static constexpr bool is_zero(std::size_t i, std::size_t j) {
    return detail::bit_of(Zero0, Zero1, Zero2, Zero3, i * C + j);
  }
  /// Entry (i, j) is exactly one for every argument.
  static constexpr bool is_one(std::size_t i, std::size_t j) {
    return detail::bit_of(One0, One1, One2, One3, i * C + j);
  }
  /// Entry (i, j) carries data.
  static constexpr bool is_free(std::size_t i, std::size_t j) {
    return !is_zero(i, j) && !is_one(i, j);
  }
};

/// A pattern with no structural entries.
template <std::size_t R, std::size_t C>
using Dense = Pattern<R, C>;

namespace detail {
/// Word w of the zero (ones = false) or one mask of the pattern whose entry (i, j) is
/// entry Map::source_row(i, j), Map::source_col(i, j) of P.
template <typename P, typename Map>
constexpr std::uint64_t mapped_word(std::size_t w, bool ones) {
  std::uint64_t out = 0;
  for (std::size_t b = 0; b < 64; ++b) {
    const std::size_t idx = w * 64 + b;
    if (idx >= Map::kRows * Map::kCols) break;
    const std::size_t i = idx / Map::kCols;
    const std::size_t j = idx % Map::kCols;
    const std::size_t si = Map::source_row(i, j);
    const std::size_t sj = Map::source_col(i, j);
    if (ones ? P::is_one(si, sj) : P::is_zero(si, sj)) out |= std::uint64_t{1} << b;
  }
  return out;
}

template <typename P, typename Map>
using Mapped = Pattern<Map::kRows, Map::kCols, mapped_word<P, Map>(0, false), mapped_word<P, Map>(0, true),
                       mapped_word<P, Map>(1, false), mapped_word<P, Map>(1, true), mapped_word<P, Map>(2, false),
                       mapped_word<P, Map>(2, true), mapped_word<P, Map>(3, false), mapped_word<P, Map>(3, true)>;

template <typename P>
struct TransposeMap {
  static constexpr std::size_t kRows = P::kCols;
  static constexpr std::size_t kCols = P::kRows;
  static constexpr std::size_t source_row(std::size_t /*i*/, std::size_t j) { return j; }
  static constexpr std::size_t source_col(std::size_t i, std::size_t /*j*/) { return i; }
};

template <typename P, std::size_t Row>
struct RowMap {
  static_assert(Row < P::kRows, "row outside the pattern");
  static constexpr std::size_t kRows = 1;
  static constexpr std::size_t kCols = P::kCols;
  static constexpr std::size_t source_row(std::size_t /*i*/, std::size_t /*j*/) { return Row; }
  static constexpr std::size_t source_col(std::size_t /*i*/, std::size_t j) { return j; }
};
}  // namespace detail

/// Pattern of the transpose.
template <typename P>
using Transposed = detail::Mapped<P, detail::TransposeMap<P>>;

/// Pattern of row `Row` of P (1×C).
template <typename P, std::size_t Row>
using RowOf = detail::Mapped<P, detail::RowMap<P, Row>>;

}  // namespace oneshot
