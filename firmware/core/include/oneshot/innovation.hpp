/// @file innovation.hpp
/// @brief Output residual y − C x̂ and the gain update x̂ + K e, shared by every observer.
#pragma once

#include <cstddef>

#include "oneshot/accumulator.hpp"
#include "oneshot/matrix.hpp"
#include "oneshot/structured_ops.hpp"

namespace oneshot {

/// e = y − C x (C with pattern CP).
template <typename Fmt, typename CP, std::size_t N, std::size_t P>
constexpr Vector<typename Fmt::State, P> innovation(const Vector<typename Fmt::State, P>& y,
                                                    const Matrix<typename Fmt::Transition, P, N>& c,
                                                    const Vector<typename Fmt::State, N>& x) {
  Vector<typename Fmt::State, P> e;
  for (std::size_t o = 0; o < P; ++o) {
    Accumulator<typename Fmt::State> acc;
    acc.add(y[o]);
    accumulate_row<CP, RowSign::kSubtract>(acc, c, o, x);
    e[o] = acc.value();
  }
  return e;
}

/// x ← x + K e.
template <typename Fmt, typename SK, std::size_t N, std::size_t P>
constexpr void add_gain_times(Vector<typename Fmt::State, N>& x, const Matrix<SK, N, P>& k,
                              const Vector<typename Fmt::State, P>& e) {
  for (std::size_t i = 0; i < N; ++i) {
    Accumulator<typename Fmt::State> acc;
    acc.add(x[i]);
    for (std::size_t o = 0; o < P; ++o) acc.add_product(k(i, o), e[o]);
    x[i] = acc.value();
  }
}

}  // namespace oneshot
