/// @file number_text.hpp
/// @brief Numbers as text for tables, labels and reports: the printf forms in one place.
#pragma once

#include <cstdio>
#include <string>

namespace oneshot::util {

/// `v` with `significant` significant digits, shortest form (printf "%.*g"; "nan", "inf").
inline std::string format_g(double v, int significant = 6) {
  char b[48];
  std::snprintf(b, sizeof b, "%.*g", significant, v);
  return b;
}

/// `v` fixed-point with `decimals` decimals (printf "%.*f"; with `sign`, "%+.*f": a difference).
inline std::string format_f(double v, int decimals, bool sign = false) {
  char b[48];
  std::snprintf(b, sizeof b, sign ? "%+.*f" : "%.*f", decimals, v);
  return b;
}

}  // namespace oneshot::util
