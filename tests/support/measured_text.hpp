/// @file measured_text.hpp
/// @brief Measured figures as text for the test report ("[ measured ] ..." lines).
#pragma once

#include <cstdio>
#include <string>

namespace oneshot::test {

/// `x` in scientific notation with four significant digits (%.3e), e.g. "1.234e-07".
inline std::string sci(double x) {
  char b[32];
  std::snprintf(b, sizeof b, "%.3e", x);
  return b;
}

}  // namespace oneshot::test
