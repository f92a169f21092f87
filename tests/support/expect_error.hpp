/// @file expect_error.hpp
/// @brief Refusal oracles: a call must throw the expected error type, naming what is wrong.
#pragma once

#include <gtest/gtest.h>

#include <exception>
#include <initializer_list>
#include <string>

namespace oneshot::test {

/// Runs `f`, which must throw an `E` whose message contains every one of `parts`: one
/// failure if nothing is thrown, one per missing part; another exception type propagates
/// (the test errors). Returns the message ("" if nothing was thrown) for further checks.
template <typename E, typename F>
std::string expect_error_naming(F&& f, std::initializer_list<const char*> parts) {
  try {
    f();
  } catch (const E& e) {
    const std::string what = e.what();
    for (const char* p : parts) EXPECT_NE(what.find(p), std::string::npos) << what << "\n  lacks: " << p;
    return what;
  }
  ADD_FAILURE() << "nothing thrown; expected an error naming " << (parts.size() != 0 ? *parts.begin() : "");
  return {};
}

/// The message of the `E` that `f` throws, or `if_none` when `f` returns (another exception
/// type propagates).
template <typename E = std::exception, typename F>
std::string message_of(F&& f, const char* if_none = "(no exception)") {
  try {
    f();
  } catch (const E& e) {
    return e.what();
  }
  return if_none;
}

}  // namespace oneshot::test
