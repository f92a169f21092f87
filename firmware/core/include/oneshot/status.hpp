/// @file status.hpp
/// @brief Result codes of fallible core maths (no exceptions in the core).
#pragma once

#include <cstdint>

namespace oneshot {

/// Outcome of a fallible core operation; `kOk` is the only unconditional success.
enum class Status : std::uint8_t {
  kOk = 0,            ///< Exact result.
  kExtended,          ///< Result exact, time beyond the table obtained by composition.
  kClamped,           ///< Input time clamped into the supported range; result approximate.
  kSingular,          ///< A pivot or innovation variance was not positive / not invertible.
  kOutOfRange,        ///< Input outside what the routine supports (e.g. norm too large).
  kOverflow,          ///< Fixed-point saturation occurred during the computation.
  kNotConverged,      ///< An iterative routine hit its iteration bound.
};

/// True when the result can be used as is (exact or exactly extended).
constexpr bool is_exact(Status s) { return s == Status::kOk || s == Status::kExtended; }

/// Keeps the first non-ok status of a sequence of operations.
constexpr Status first_failure(Status current, Status next) {
  return current == Status::kOk ? next : current;
}

/// Short name for logs and error messages (host side).
constexpr const char* to_string(Status s) {
  switch (s) {
    case Status::kOk: return "ok";
    case Status::kExtended: return "extended";
    case Status::kClamped: return "clamped";
    case Status::kSingular: return "singular";
    case Status::kOutOfRange: return "out_of_range";
    case Status::kOverflow: return "overflow";
    case Status::kNotConverged: return "not_converged";
  }
  return "unknown";
}

}  // namespace oneshot
