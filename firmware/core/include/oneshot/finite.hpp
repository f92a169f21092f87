/// @file finite.hpp
/// @brief The core's finiteness test, freestanding: a float or double is finite when its
///        exponent field is not all ones (IEEE 754 binary32/binary64); fixed point is always
///        finite. Reads the bits, so it holds under any floating-point optimisation flags.
#pragma once

#include <cstddef>
#include <cstdint>
#include <type_traits>

#include "oneshot/matrix.hpp"

namespace oneshot {

/// True when v is neither NaN nor ±∞ (fixed point: always). Dispatches on the size of
/// the type, so a 32-bit double (AVR) is read as binary32.
template <typename S>
inline bool is_finite(S v) {
  if constexpr (!std::is_floating_point_v<S>) {
    return true;  // fixed point: every raw value is a finite number
  } else if constexpr (sizeof(S) == 4) {
    std::uint32_t bits = 0;
    __builtin_memcpy(&bits, &v, 4);
    return (bits & 0x7F800000U) != 0x7F800000U;  // exponent all ones: ∞ or NaN
  } else {
    static_assert(sizeof(S) == 8, "binary32 or binary64 expected");
    std::uint64_t bits = 0;
    __builtin_memcpy(&bits, &v, 8);
    return (bits & 0x7FF0000000000000ULL) != 0x7FF0000000000000ULL;
  }
}

/// True when every element of m is finite.
template <typename S, std::size_t R, std::size_t C>
inline bool all_finite(const Matrix<S, R, C>& m) {
  for (std::size_t i = 0; i < R * C; ++i)
    if (!is_finite(m[i])) return false;
  return true;
}

/// True when the scalar v is finite (the overload for scalar payloads).
template <typename S, typename = std::enable_if_t<std::is_arithmetic_v<S>>>
inline bool all_finite(S v) {
  return is_finite(v);
}

}  // namespace oneshot
