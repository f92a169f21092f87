/// @file numre_structure.hpp
/// @brief Compile-time nonzero structure of a NUMRE model, and the products that skip its
///        structural zeros in straight-line code (issue 25).
///
/// A structure type gives, for an N-state model, row masks of A (bit j of row i: A_ij may be
/// nonzero) and masks of B, C, C̄:
///     static constexpr std::uint32_t row(std::size_t i);   kB, kC, kCbar
/// The products below unroll at compile time and leave out the masked-off terms, so
///     (A x)_i = Σ_{j ∈ row(i)} A_ij x_j
/// is the dense sum with exact zeros skipped (the same value). A^j keeps its zeros inside
/// the closure R_i = ∪_{k≥1} pattern(A^k)_i, computed here from the masks:
///     R_i ← row(i);  R_i ← R_i ∪ ⋃_{l ∈ R_i} row(l)   (N times).
/// A model with a nonzero outside its structure must be refused before use (fits()):
/// the node would silently drop it. DenseModelStructure (every bit set) fits every model.
#pragma once

#include <cstddef>
#include <cstdint>
#include <type_traits>
#include <utility>

#include "oneshot/matrix.hpp"

namespace oneshot::node {

/// Every entry may be nonzero (the default: no assumption about the model).
template <std::size_t N>
struct DenseModelStructure {
  static_assert(N <= 32, "row masks are 32-bit");
  /// Row mask of A: all N columns.
  static constexpr std::uint32_t row(std::size_t /*i*/) { return N == 32 ? ~0U : (1U << N) - 1U; }
  static constexpr std::uint32_t kB = row(0);     ///< B: every row.
  static constexpr std::uint32_t kC = row(0);     ///< C: every column.
  static constexpr std::uint32_t kCbar = row(0);  ///< C̄: every column.
};

/// Calls f(std::integral_constant<std::size_t, I>) for I = B … E − 1 (compile-time loop).
template <std::size_t B, std::size_t E>
struct Unrolled {
  /// Runs the loop.
  template <typename F>
  [[gnu::always_inline]] static constexpr void run(F&& f) {
    if constexpr (B < E) {
      f(std::integral_constant<std::size_t, B>{});
      Unrolled<B + 1, E>::run(f);
    }
  }
};

/// Set bits of a mask.
constexpr std::uint64_t mask_count(std::uint32_t m) {
  std::uint64_t n = 0;
  for (; m != 0; m &= m - 1) ++n;
  return n;
}

/// Row i of the closure of Structure's A: columns any power A^k (k ≥ 1) may fill.
template <typename Structure, std::size_t N>
constexpr std::uint32_t closure_row(std::size_t i) {
  std::uint32_t r = Structure::row(i);
  for (std::size_t pass = 0; pass < N; ++pass)
    for (std::size_t l = 0; l < N; ++l)
      if (((r >> l) & 1U) != 0) r |= Structure::row(l);
  return r;
}

/// The closure of Structure as a structure (for the powers A^j of the span table).
template <typename Structure, std::size_t N>
struct ClosureStructure {
  /// Row mask of A^j, any j ≥ 1.
  static constexpr std::uint32_t row(std::size_t i) { return closure_row<Structure, N>(i); }
  static constexpr std::uint32_t kB = Structure::kB;        ///< As Structure.
  static constexpr std::uint32_t kC = Structure::kC;        ///< As Structure.
  static constexpr std::uint32_t kCbar = Structure::kCbar;  ///< As Structure.
};

/// Nonzero entries of A the structure keeps.
template <typename Structure, std::size_t N>
constexpr std::uint64_t structure_size() {
  std::uint64_t n = 0;
  for (std::size_t i = 0; i < N; ++i) n += mask_count(Structure::row(i));
  return n;
}

/// Σ_{j ∈ mask} v_j x_j (row vector v), unrolled, ascending j.
template <std::uint32_t kMask, typename S, std::size_t N>
constexpr S masked_dot(const Matrix<S, 1, N>& v, const Vector<S, N>& x) {
  S acc = S(0);
  Unrolled<0, N>::run([&](auto jc) {
    constexpr std::size_t j = decltype(jc)::value;
    if constexpr (((kMask >> j) & 1U) != 0) acc = acc + v[j] * x[j];
  });
  return acc;
}

/// Σ_{j ∈ row(I)} A_Ij x_j of row I of A over Structure's row mask, unrolled, ascending j from
/// a zero accumulator (the summation order every product below keeps). Forced inline, with
/// its column loop: it is the inner loop of the M4F arrival, whose instruction count depends
/// on straight-line code.
template <typename Structure, std::size_t I, typename S, std::size_t N>
[[gnu::always_inline]] inline constexpr S masked_row(const Matrix<S, N, N>& a, const Vector<S, N>& x) {
  S acc = S(0);
  Unrolled<0, N>::run([&](auto jc) __attribute__((always_inline)) {
    constexpr std::size_t j = decltype(jc)::value;
    if constexpr (((Structure::row(I) >> j) & 1U) != 0) acc = acc + a(I, j) * x[j];
  });
  return acc;
}

/// y = A x over Structure's rows, unrolled; returns the multiply-adds.
template <typename Structure, typename S, std::size_t N>
constexpr std::uint64_t masked_product(const Matrix<S, N, N>& a, const Vector<S, N>& x, Vector<S, N>& y) {
  Unrolled<0, N>::run([&](auto ic) __attribute__((always_inline)) {
    constexpr std::size_t i = decltype(ic)::value;
    y[i] = masked_row<Structure, i>(a, x);
  });
  return structure_size<Structure, N>();
}

/// y = A x + B u over Structure's rows and kB, unrolled, each row summed as (Σ_j A_ij x_j) + B_i u
/// (y must not alias x); returns the multiply-adds.
template <typename Structure, typename S, std::size_t N>
constexpr std::uint64_t masked_step(const Matrix<S, N, N>& a, const Vector<S, N>& b, const Vector<S, N>& x, S u,
                                    Vector<S, N>& y) {
  Unrolled<0, N>::run([&](auto ic) __attribute__((always_inline)) {
    constexpr std::size_t i = decltype(ic)::value;
    S acc = masked_row<Structure, i>(a, x);
    if constexpr (((Structure::kB >> i) & 1U) != 0) acc = acc + b[i] * u;
    y[i] = acc;
  });
  return structure_size<Structure, N>() + mask_count(Structure::kB);
}

/// P ← A P Aᵀ for a symmetric P over Structure's rows (upper triangle, mirrored), unrolled
/// over the columns of each row; returns the multiply-adds.
template <typename Structure, typename S, std::size_t N>
constexpr std::uint64_t masked_sandwich(const Matrix<S, N, N>& a, Matrix<S, N, N>& p) {
  Matrix<S, N, N> t;  // T = A P
  Unrolled<0, N>::run([&](auto ic) {
    constexpr std::size_t i = decltype(ic)::value;
    for (std::size_t c = 0; c < N; ++c) {
      S acc = S(0);
      Unrolled<0, N>::run([&](auto lc) {
        constexpr std::size_t l = decltype(lc)::value;
        if constexpr (((Structure::row(i) >> l) & 1U) != 0) acc = acc + a(i, l) * p(l, c);
      });
      t(i, c) = acc;
    }
  });
  std::uint64_t macs = N * structure_size<Structure, N>();
  Unrolled<0, N>::run([&](auto kc) {  // (T Aᵀ)_ik = Σ_l T_il A_kl, i ≤ k
    constexpr std::size_t k = decltype(kc)::value;
    for (std::size_t i = 0; i <= k; ++i) {
      S acc = S(0);
      Unrolled<0, N>::run([&](auto lc) {
        constexpr std::size_t l = decltype(lc)::value;
        if constexpr (((Structure::row(k) >> l) & 1U) != 0) acc = acc + t(i, l) * a(k, l);
      });
      p(i, k) = acc;
      p(k, i) = acc;
    }
    macs += (k + 1) * mask_count(Structure::row(k));
  });
  return macs;
}

/// True when every nonzero of A, B, C, C̄ lies inside Structure (the model may use it).
template <typename Structure, typename S, std::size_t N>
constexpr bool fits_structure(const Matrix<S, N, N>& a, const Vector<S, N>& b, const Matrix<S, 1, N>& c,
                              const Matrix<S, 1, N>& c_bar) {
  for (std::size_t i = 0; i < N; ++i) {
    for (std::size_t j = 0; j < N; ++j)
      if (a(i, j) != S(0) && ((Structure::row(i) >> j) & 1U) == 0) return false;
    if (b[i] != S(0) && ((Structure::kB >> i) & 1U) == 0) return false;
    if (c[i] != S(0) && ((Structure::kC >> i) & 1U) == 0) return false;
    if (c_bar[i] != S(0) && ((Structure::kCbar >> i) & 1U) == 0) return false;
  }
  return true;
}

}  // namespace oneshot::node
