/// @file status.hpp
/// @brief Result codes of fallible core maths (no exceptions in the core), ordered by severity.
///
/// The numeric values are part of the PIL protocol and the C job and never change; the
/// order of severity is severity() (exact < approximate < a step skipped < no result):
///   kOk < kExtended < kClamped < kOverflow < kNotConverged < kSingular < kOutOfRange < kNonFinite.
/// A sequence of operations reports worst_of() its statuses, so no failure ever hides
/// behind a milder one (a kSingular correction after a kExtended prediction is kSingular).
#pragma once

#include <cstdint>

namespace oneshot {

/// Outcome of a fallible core operation; `kOk` is the only unconditional success. The type is
/// [[nodiscard]]: every function returning a Status must have its result used (or cast to void
/// where a failure is impossible, with the reason beside it).
enum class [[nodiscard]] Status : std::uint8_t {
  kOk = 0,            ///< Exact result.
  kExtended,          ///< Result exact, time beyond the table obtained by composition.
  kClamped,           ///< Input time clamped into the supported range; result approximate.
  kSingular,          ///< A pivot or innovation variance was not positive / not invertible.
  kOutOfRange,        ///< Input outside what the routine supports (e.g. norm too large).
  kOverflow,          ///< Fixed-point saturation occurred during the computation.
  kNotConverged,      ///< An iterative routine hit its iteration bound.
  kNonFinite,         ///< The result turned NaN or ±∞: discarded, the state reset to its design initial value.
};

/// Rank of s, 0 for kOk: approximate results (clamped, saturated, not converged) rank
/// below a skipped step (singular), which ranks below no result at all (out of range), which
/// ranks below a non-finite result (state lost and reset).
constexpr std::uint8_t severity(Status s) {
  switch (s) {
    case Status::kOk: return 0;
    case Status::kExtended: return 1;
    case Status::kClamped: return 2;
    case Status::kOverflow: return 3;
    case Status::kNotConverged: return 4;
    case Status::kSingular: return 5;
    case Status::kOutOfRange: return 6;
    case Status::kNonFinite: return 7;
  }
  return 8;  // not a Status value: worse than any
}

/// The more severe of a and b (a on ties): the status of a and b done in sequence.
[[nodiscard]] constexpr Status worst_of(Status a, Status b) { return severity(b) > severity(a) ? b : a; }

/// True when the result can be used as is (exact or exactly extended).
constexpr bool is_exact(Status s) { return s == Status::kOk || s == Status::kExtended; }

/// Status of a sequence so far combined with the next operation's: the worst of both
/// (kept under its historical name; it no longer returns a milder earlier status).
[[nodiscard]] constexpr Status first_failure(Status current, Status next) { return worst_of(current, next); }

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
    case Status::kNonFinite: return "non_finite";
  }
  return "unknown";
}

}  // namespace oneshot
