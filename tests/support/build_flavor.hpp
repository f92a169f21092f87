/// @file build_flavor.hpp
/// @brief Which build the tests run in. The sanitized build (asan preset) runs the long
///        statistical runs shortened: it checks memory and undefined behaviour on the same code
///        paths, the release stage (ci preset) runs them at full length.
#pragma once

namespace oneshot::test {

/// True in the AddressSanitizer + UndefinedBehaviorSanitizer build (ONESHOT_SANITIZE).
inline constexpr bool kSanitizedBuild = ONESHOT_TEST_SANITIZED != 0;

/// A long run's length: `full` in the release build, `full / divisor` under the sanitizers.
template <typename T>
constexpr T sanitized_length(T full, T divisor) {
  return kSanitizedBuild ? full / divisor : full;
}

}  // namespace oneshot::test
