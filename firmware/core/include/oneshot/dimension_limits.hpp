/// @file dimension_limits.hpp
/// @brief The largest plant the core, the tables, the design step and the plant file support.
///
/// One place for the limits: the core's templates static_assert against them, the plant
/// file refuses a plant beyond them with the limit named, and the design step sizes its
/// work arrays from them. A build for a smaller MCU may refuse more (its own limit, named).
#pragma once

#include <cstddef>

namespace oneshot {

/// Largest state dimension n.
inline constexpr std::size_t kMaxStates = 16;
/// Largest input dimension m.
inline constexpr std::size_t kMaxInputs = 4;
/// Largest output dimension p.
inline constexpr std::size_t kMaxOutputs = 4;
/// Largest disturbance-input dimension (columns of B_w).
inline constexpr std::size_t kMaxDisturbances = 4;

/// True when (n, m, p) is within the supported limits (usable in static_assert).
constexpr bool within_dimension_limits(std::size_t n, std::size_t m, std::size_t p) {
  return n >= 1 && n <= kMaxStates && m >= 1 && m <= kMaxInputs && p >= 1 && p <= kMaxOutputs;
}

}  // namespace oneshot
