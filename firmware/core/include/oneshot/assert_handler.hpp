/// @file assert_handler.hpp
/// @brief The single invariant-check point of the core.
///
/// Every invariant goes through ONESHOT_ASSERT, which calls oneshot::assert_failed().
/// The core only declares it; each port defines it (host: report and abort, or a test
/// failure; MCU: record and trap). Invariants are programming errors, not run-time
/// conditions: fallible maths returns a Status instead.
#pragma once

namespace oneshot {

/// Called when an invariant does not hold; defined by the port, never returns normally.
[[noreturn]] void assert_failed(const char* file, int line, const char* expression);

}  // namespace oneshot

/// Checks an invariant; a failure goes to oneshot::assert_failed().
#define ONESHOT_ASSERT(expression)                                   \
  do {                                                               \
    if (!(expression)) {                                             \
      ::oneshot::assert_failed(__FILE__, __LINE__, #expression);     \
    }                                                                \
  } while (false)
