/// @file dimension_dispatch.hpp
/// @brief Calls a generic lambda with the compile-time dimensions of a run-time plant.
///
/// For code that needs the core's fixed-size types (the one-shot harness, the table
/// builder). Every (n, m, p) up to the dispatch limits is one instantiation of the callee,
/// so the limits here are those of the harness, not of the plant file
/// (dimension_limits.hpp): the design step itself is run-time sized and needs no dispatch.
#pragma once

#include <cstddef>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>

#include "oneshot/design/plant_description.hpp"

namespace oneshot::design {

/// Largest state dimension instantiated by with_dimensions().
inline constexpr std::size_t kDispatchMaxStates = 4;
/// Largest input dimension instantiated by with_dimensions().
inline constexpr std::size_t kDispatchMaxInputs = 2;
/// Largest output dimension instantiated by with_dimensions().
inline constexpr std::size_t kDispatchMaxOutputs = 2;

/// Compile-time size carried as a value.
template <std::size_t V>
using Size = std::integral_constant<std::size_t, V>;

namespace detail {
template <typename F>
using DispatchResult = std::invoke_result_t<F&, Size<1>, Size<1>, Size<1>>;

template <std::size_t N, std::size_t M, std::size_t P, typename F>
DispatchResult<F> dispatch_p(std::size_t p, F& f) {
  if constexpr (P > kDispatchMaxOutputs) {
    throw std::invalid_argument(std::to_string(p) + " outputs exceed the " + std::to_string(kDispatchMaxOutputs) +
                                " this tool is instantiated for (kDispatchMaxOutputs)");
  } else {
    if (p == P) return f(Size<N>{}, Size<M>{}, Size<P>{});
    return dispatch_p<N, M, P + 1>(p, f);
  }
}
template <std::size_t N, std::size_t M, typename F>
DispatchResult<F> dispatch_m(std::size_t m, std::size_t p, F& f) {
  if constexpr (M > kDispatchMaxInputs) {
    throw std::invalid_argument(std::to_string(m) + " inputs exceed the " + std::to_string(kDispatchMaxInputs) +
                                " this tool is instantiated for (kDispatchMaxInputs)");
  } else {
    if (m == M) return dispatch_p<N, M, 1>(p, f);
    return dispatch_m<N, M + 1>(m, p, f);
  }
}
template <std::size_t N, typename F>
DispatchResult<F> dispatch_n(std::size_t n, std::size_t m, std::size_t p, F& f) {
  if constexpr (N > kDispatchMaxStates) {
    throw std::invalid_argument(std::to_string(n) + " states exceed the " + std::to_string(kDispatchMaxStates) +
                                " this tool is instantiated for (kDispatchMaxStates)");
  } else {
    if (n == N) return dispatch_m<N, 1>(m, p, f);
    return dispatch_n<N + 1>(n, m, p, f);
  }
}
}  // namespace detail

/// f(Size<n>{}, Size<m>{}, Size<p>{}) for 1 ≤ n ≤ kDispatchMaxStates, 1 ≤ m ≤
/// kDispatchMaxInputs, 1 ≤ p ≤ kDispatchMaxOutputs; std::invalid_argument naming the limit
/// otherwise. Every instantiation of f
/// must return the same type.
template <typename F>
detail::DispatchResult<F> with_dimensions(std::size_t n, std::size_t m, std::size_t p, F&& f) {
  return detail::dispatch_n<1>(n, m, p, f);
}

}  // namespace oneshot::design
