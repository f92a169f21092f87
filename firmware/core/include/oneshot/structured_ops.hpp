/// @file structured_ops.hpp
/// @brief Pattern-aware matrix kernels with a chosen output format.
///
/// Each kernel takes the compile-time Pattern of its structured operands: structural
/// zeros are skipped and structural ones turn a multiplication into a copy. The order
/// of operations is fixed by the code (left to right over k), so a host build and an MCU
/// build with the same IEEE format produce bit-identical results.
#pragma once

#include <cstddef>

#include "oneshot/accumulator.hpp"
#include "oneshot/matrix.hpp"
#include "oneshot/pattern.hpp"

namespace oneshot {

namespace detail {

/// acc += a·b honouring the structure of both factors.
template <typename Out, typename SA, typename SB>
constexpr void accumulate_term(Accumulator<Out>& acc, bool a_zero, bool a_one, const SA& a,
                               bool b_zero, bool b_one, const SB& b) {
  if (a_zero || b_zero) return;
  if (a_one && b_one) {
    acc.add(ScalarTraits<Out>::one());
  } else if (a_one) {
    acc.add(b);
  } else if (b_one) {
    acc.add(a);
  } else {
    acc.add_product(a, b);
  }
}

/// acc += Q(i, j), Q with pattern PQ (a structural one adds 1, a structural zero nothing).
template <typename PQ, typename Out, typename SQ, std::size_t N>
[[gnu::always_inline]] constexpr void add_patterned(Accumulator<Out>& acc, const Matrix<SQ, N, N>& q, std::size_t i, std::size_t j) {
  if (PQ::is_one(i, j)) {
    acc.add(ScalarTraits<Out>::one());
  } else if (!PQ::is_zero(i, j)) {
    acc.add(q(i, j));
  }
}

template <typename P, std::size_t R, std::size_t C>
constexpr void check_pattern_shape() {
  static_assert(P::kRows == R && P::kCols == C, "pattern shape does not match the matrix");
}

}  // namespace detail

/// Sign of a row term in accumulate_row().
enum class RowSign : bool { kAdd, kSubtract };

/// acc ± Σ_k A(r, k)·v_k, A with pattern PA: a structural zero is skipped, a structural one
/// adds (subtracts) v_k itself.
template <typename PA, RowSign kSign, typename Out, typename SA, typename SV, std::size_t R, std::size_t K>
[[gnu::always_inline]] constexpr void accumulate_row(Accumulator<Out>& acc, const Matrix<SA, R, K>& a, std::size_t r,
                              const Vector<SV, K>& v) {
  for (std::size_t k = 0; k < K; ++k) {
    if (PA::is_zero(r, k)) continue;
    if constexpr (kSign == RowSign::kAdd) {
      if (PA::is_one(r, k)) {
        acc.add(v[k]);
      } else {
        acc.add_product(a(r, k), v[k]);
      }
    } else if (PA::is_one(r, k)) {
      acc.sub(v[k]);
    } else {
      acc.sub_product(a(r, k), v[k]);
    }
  }
}

/// A·B in format Out, A and B with patterns PA, PB.
template <typename Out, typename PA, typename PB, typename SA, typename SB, std::size_t R,
          std::size_t K, std::size_t C>
constexpr Matrix<Out, R, C> product(const Matrix<SA, R, K>& a, const Matrix<SB, K, C>& b) {
  detail::check_pattern_shape<PA, R, K>();
  detail::check_pattern_shape<PB, K, C>();
  Matrix<Out, R, C> out{NoInit{}};
  for (std::size_t i = 0; i < R; ++i)
    for (std::size_t j = 0; j < C; ++j) {
      Accumulator<Out> acc;
      for (std::size_t k = 0; k < K; ++k)
        detail::accumulate_term(acc, PA::is_zero(i, k), PA::is_one(i, k), a(i, k), PB::is_zero(k, j),
                                PB::is_one(k, j), b(k, j));
      out(i, j) = acc.value();
    }
  return out;
}

/// A·x + B·u in format Out (the affine prediction Φx + Γu), one rounding per entry.
template <typename Out, typename PA, typename PB, typename SA, typename SX, typename SB,
          typename SU, std::size_t N, std::size_t M, std::size_t C>
constexpr Matrix<Out, N, C> affine(const Matrix<SA, N, N>& a, const Matrix<SX, N, C>& x,
                                   const Matrix<SB, N, M>& b, const Matrix<SU, M, C>& u) {
  detail::check_pattern_shape<PA, N, N>();
  detail::check_pattern_shape<PB, N, M>();
  Matrix<Out, N, C> out{NoInit{}};
  for (std::size_t i = 0; i < N; ++i)
    for (std::size_t j = 0; j < C; ++j) {
      Accumulator<Out> acc;
      for (std::size_t k = 0; k < N; ++k)
        detail::accumulate_term(acc, PA::is_zero(i, k), PA::is_one(i, k), a(i, k), false, false,
                                x(k, j));
      for (std::size_t k = 0; k < M; ++k)
        detail::accumulate_term(acc, PB::is_zero(i, k), PB::is_one(i, k), b(i, k), false, false,
                                u(k, j));
      out(i, j) = acc.value();
    }
  return out;
}

/// A·P·Aᵀ (+ Q) in format Out for symmetric P (and Q, pattern PQ); only upper triangles
/// are read and the result is exactly symmetric.
template <typename Out, typename PA, typename PQ, bool kAddQ, typename SA, typename SP,
          typename SQ, std::size_t N>
constexpr Matrix<Out, N, N> congruence_impl(const Matrix<SA, N, N>& a, const Matrix<SP, N, N>& p,
                                            const Matrix<SQ, N, N>& q) {
  detail::check_pattern_shape<PA, N, N>();
  detail::check_pattern_shape<PQ, N, N>();
  // T = A·P (full rows of T needed), then out_ij = Σ_k T_ik A_jk for j ≥ i.
  Matrix<Out, N, N> t{NoInit{}};
  for (std::size_t i = 0; i < N; ++i)
    for (std::size_t j = 0; j < N; ++j) {
      Accumulator<Out> acc;
      for (std::size_t k = 0; k < N; ++k) {
        const std::size_t r = k < j ? k : j;  // read the upper triangle of P only
        const std::size_t c = k < j ? j : k;
        detail::accumulate_term(acc, PA::is_zero(i, k), PA::is_one(i, k), a(i, k), false, false,
                                p(r, c));
      }
      t(i, j) = acc.value();
    }
  Matrix<Out, N, N> out{NoInit{}};  // upper triangle written, lower mirrored
  fill_symmetric(out, [&](std::size_t i, std::size_t j) __attribute__((always_inline)) {
    Accumulator<Out> acc;
    for (std::size_t k = 0; k < N; ++k)
      detail::accumulate_term(acc, false, false, t(i, k), PA::is_zero(j, k), PA::is_one(j, k), a(j, k));
    if constexpr (kAddQ) detail::add_patterned<PQ>(acc, q, i, j);
    return acc.value();
  });
  return out;
}

/// A·P·Aᵀ + Q for symmetric P, Q.
template <typename Out, typename PA, typename PQ, typename SA, typename SP, typename SQ,
          std::size_t N>
constexpr Matrix<Out, N, N> congruence_add(const Matrix<SA, N, N>& a, const Matrix<SP, N, N>& p,
                                           const Matrix<SQ, N, N>& q) {
  return congruence_impl<Out, PA, PQ, true>(a, p, q);
}

/// A·P·Aᵀ for symmetric P.
template <typename Out, typename PA, typename SA, typename SP, std::size_t N>
constexpr Matrix<Out, N, N> congruence(const Matrix<SA, N, N>& a, const Matrix<SP, N, N>& p) {
  return congruence_impl<Out, PA, Dense<N, N>, false>(a, p, p);
}

/// P + Q for symmetric P, Q (upper triangle, mirrored), Q with pattern PQ.
template <typename Out, typename PQ, typename SP, typename SQ, std::size_t N>
constexpr Matrix<Out, N, N> symmetric_add(const Matrix<SP, N, N>& p, const Matrix<SQ, N, N>& q) {
  detail::check_pattern_shape<PQ, N, N>();
  Matrix<Out, N, N> out{NoInit{}};  // upper triangle written, lower mirrored
  fill_symmetric(out, [&](std::size_t i, std::size_t j) __attribute__((always_inline)) {
    Accumulator<Out> acc;
    acc.add(p(i, j));
    detail::add_patterned<PQ>(acc, q, i, j);
    return acc.value();
  });
  return out;
}

/// Fills the structural entries of `m` from pattern P (ones to 1, zeros to 0).
template <typename P, typename S, std::size_t R, std::size_t C>
constexpr void apply_pattern(Matrix<S, R, C>& m) {
  detail::check_pattern_shape<P, R, C>();
  for (std::size_t i = 0; i < R; ++i)
    for (std::size_t j = 0; j < C; ++j) {
      if (P::is_zero(i, j)) m(i, j) = ScalarTraits<S>::zero();
      if (P::is_one(i, j)) m(i, j) = ScalarTraits<S>::one();
    }
}

}  // namespace oneshot
