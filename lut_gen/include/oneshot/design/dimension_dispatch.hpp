/// @file dimension_dispatch.hpp
/// @brief Calls a generic lambda with the compile-time dimensions of a run-time plant.
#pragma once

#include <cstddef>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>

#include "oneshot/design/plant_description.hpp"

namespace oneshot::design {

/// Compile-time size carried as a value.
template <std::size_t V>
using Size = std::integral_constant<std::size_t, V>;

namespace detail {
template <typename F>
using DispatchResult = std::invoke_result_t<F&, Size<1>, Size<1>, Size<1>>;

template <std::size_t N, std::size_t M, std::size_t P, typename F>
DispatchResult<F> dispatch_p(std::size_t p, F& f) {
  if constexpr (P > kMaxOutputs) {
    throw std::invalid_argument("unsupported output dimension " + std::to_string(p));
  } else {
    if (p == P) return f(Size<N>{}, Size<M>{}, Size<P>{});
    return dispatch_p<N, M, P + 1>(p, f);
  }
}
template <std::size_t N, std::size_t M, typename F>
DispatchResult<F> dispatch_m(std::size_t m, std::size_t p, F& f) {
  if constexpr (M > kMaxInputs) {
    throw std::invalid_argument("unsupported input dimension " + std::to_string(m));
  } else {
    if (m == M) return dispatch_p<N, M, 1>(p, f);
    return dispatch_m<N, M + 1>(m, p, f);
  }
}
template <std::size_t N, typename F>
DispatchResult<F> dispatch_n(std::size_t n, std::size_t m, std::size_t p, F& f) {
  if constexpr (N > kMaxStates) {
    throw std::invalid_argument("unsupported state dimension " + std::to_string(n));
  } else {
    if (n == N) return dispatch_m<N, 1>(m, p, f);
    return dispatch_n<N + 1>(n, m, p, f);
  }
}
}  // namespace detail

/// f(Size<n>{}, Size<m>{}, Size<p>{}) for 1 ≤ n ≤ kMaxStates, 1 ≤ m ≤ kMaxInputs,
/// 1 ≤ p ≤ kMaxOutputs; std::invalid_argument otherwise. Every instantiation of f
/// must return the same type.
template <typename F>
detail::DispatchResult<F> with_dimensions(std::size_t n, std::size_t m, std::size_t p, F&& f) {
  return detail::dispatch_n<1>(n, m, p, f);
}

}  // namespace oneshot::design
