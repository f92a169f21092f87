/// @file fuzz_oracle.hpp
/// @brief What every harness checks beyond "no crash": accepted input gives sane output.
#pragma once

#include <cstdio>
#include <cstdlib>
#include <string>

namespace oneshot::fuzz {

/// Stops the run with `what` when `ok` is false: libFuzzer saves the input as a crash.
inline void require(bool ok, const std::string& what) {
  if (ok) return;
  std::fprintf(stderr, "oracle failed: %s\n", what.c_str());
  std::abort();
}

}  // namespace oneshot::fuzz
