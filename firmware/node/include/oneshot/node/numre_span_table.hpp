/// @file numre_span_table.hpp
/// @brief Design-time table of the NUMRE model's j-period transitions, so that a prediction
///        over N silent periods costs a few dense steps whatever N (issue 25).
///
/// For the model x⁺ = A x + B u + B_w w (Q = B_w W B_wᵀ) the span of j periods is
///     A^j,   W_e(j) = Σ_{c<j} A^c Q (A^c)ᵀ,   G(j) = Σ_{c<j} A^c B_w,   Γ(j) = Σ_{c<j} A^c B,
/// and two spans compose (the model is time invariant, so the order does not matter):
///     A^{a+b} = A^a A^b,   W_e(a+b) = A^a W_e(b) (A^a)ᵀ + W_e(a),
///     G(a+b) = G(a) + A^a G(b),   Γ(a+b) = Γ(a) + A^a Γ(b).
/// The table holds j = d·r^p (d = 1 … r−1, p = 0 … D−1): (r−1)·D spans built once from A
/// (no run-time exponentials). N < r^D is the sum of its base-r digits' spans (at most D of
/// them); a larger N adds whole top spans. A^j keeps the model's structural zeros inside
/// their closure (numre_structure.hpp), which the estimator's products skip.
#pragma once

#include <cstddef>
#include <cstdint>

#include "oneshot/matrix.hpp"

namespace oneshot::node {

/// P ← A P Aᵀ for a symmetric P, dense (upper triangle computed and mirrored); returns the
/// multiply-adds. The estimator skips structural zeros instead (numre_structure.hpp).
template <typename S, std::size_t N>
constexpr std::uint64_t sandwich(const Matrix<S, N, N>& a, Matrix<S, N, N>& p) {
  const Matrix<S, N, N> t = a * p;
  for (std::size_t i = 0; i < N; ++i)  // (T Aᵀ)_ik = Σ_l T_il A_kl, k ≥ i
    for (std::size_t k = i; k < N; ++k) {
      S acc = t(i, 0) * a(k, 0);
      for (std::size_t l = 1; l < N; ++l) acc = acc + t(i, l) * a(k, l);
      p(i, k) = acc;
      p(k, i) = acc;
    }
  return N * N * N + N * N * (N + 1) / 2;
}

/// Entries of a symmetric N × N matrix's upper triangle.
template <std::size_t N>
inline constexpr std::size_t kPackedSize = N * (N + 1) / 2;

/// The upper triangle of symmetric `m`, row by row.
template <typename S, std::size_t N>
constexpr void pack_upper(const Matrix<S, N, N>& m, S (&out)[kPackedSize<N>]) {
  std::size_t q = 0;
  for (std::size_t i = 0; i < N; ++i)
    for (std::size_t k = i; k < N; ++k) out[q++] = m(i, k);
}

/// The symmetric matrix of a packed upper triangle.
template <typename S, std::size_t N>
constexpr Matrix<S, N, N> unpack_upper(const S (&in)[kPackedSize<N>]) {
  Matrix<S, N, N> m;
  std::size_t q = 0;
  for (std::size_t i = 0; i < N; ++i)
    for (std::size_t k = i; k < N; ++k) {
      m(i, k) = in[q];
      m(k, i) = in[q++];
    }
  return m;
}

/// One tabulated span of j periods.
template <typename S, std::size_t N>
struct ModelSpan {
  Matrix<S, N, N> a;    ///< A^j.
  S w[kPackedSize<N>]{};  ///< W_e(j), upper triangle row by row (symmetric).
  Vector<S, N> g;       ///< G(j) = Σ_{c<j} A^c B_w.
  Vector<S, N> gamma;   ///< Γ(j) = Σ_{c<j} A^c B.
  std::uint32_t length = 0;  ///< j.
};

/// Spans j = d·r^p of the model (d = 1 … r − 1, p = 0 … D − 1), built once.
template <typename S, std::size_t N, std::size_t kRadix, std::size_t kDigits>
class NumreSpanTable {
  static_assert(kRadix >= 2 && kDigits >= 1, "span table needs radix ≥ 2 and one digit");

 public:
  using Span = ModelSpan<S, N>;  ///< One span.

  /// N below this is covered by at most kDigits spans (r^D).
  static constexpr std::uint32_t kCover = [] {
    std::uint32_t c = 1;
    for (std::size_t p = 0; p < kDigits; ++p) c *= static_cast<std::uint32_t>(kRadix);
    return c;
  }();

  /// Table of the model (A, B, B_w, Q = B_w W B_wᵀ).
  constexpr NumreSpanTable(const Matrix<S, N, N>& a, const Vector<S, N>& b, const Vector<S, N>& b_w,
                           const Matrix<S, N, N>& q) {
    Span one;
    one.a = a;
    pack_upper(q, one.w);
    one.g = b_w;
    one.gamma = b;
    one.length = 1;
    spans_[0][0] = one;
    for (std::size_t p = 0; p < kDigits; ++p) {
      if (p > 0) spans_[p][0] = compose(spans_[p - 1][kRadix - 2], spans_[p - 1][0]);
      for (std::size_t d = 1; d + 1 < kRadix; ++d) spans_[p][d] = compose(spans_[p][d - 1], spans_[p][0]);
    }
  }

  /// Calls f(span) for spans whose lengths sum to n: the base-r digits of n, then whole
  /// r^D periods as (r − 1)·r^{D−1} + r^{D−1} when n ≥ r^D.
  template <typename F>
  constexpr void for_each_span(std::uint32_t n, F&& f) const {
    for (std::size_t p = 0; p < kDigits; ++p) {
      const std::uint32_t d = n % static_cast<std::uint32_t>(kRadix);
      n /= static_cast<std::uint32_t>(kRadix);
      if (d != 0) f(spans_[p][d - 1]);
    }
    for (; n > 0; --n) {
      f(spans_[kDigits - 1][kRadix - 2]);
      f(spans_[kDigits - 1][0]);
    }
  }

  /// The span d·r^p (1 ≤ d < r).
  constexpr const Span& span(std::size_t p, std::size_t d) const { return spans_[p][d - 1]; }

 private:
  /// Span a + b from spans a and b.
  static constexpr Span compose(const Span& sa, const Span& sb) {
    Span s;
    s.a = sa.a * sb.a;
    Matrix<S, N, N> w = unpack_upper<S, N>(sb.w);
    static_cast<void>(sandwich(sa.a, w));
    pack_upper(w + unpack_upper<S, N>(sa.w), s.w);
    s.g = sa.g + sa.a * sb.g;
    s.gamma = sa.gamma + sa.a * sb.gamma;
    s.length = sa.length + sb.length;
    return s;
  }

  Span spans_[kDigits][kRadix - 1]{};
};

}  // namespace oneshot::node
