/// @file test_main.cpp
/// @brief GoogleTest main: core invariant failures become exceptions (test failures).
#include <gtest/gtest.h>

#include <string>

#include "oneshot/host/assert_hook.hpp"
#include "support/invariant_violation.hpp"

namespace {
[[noreturn]] void throw_on_assert(const char* file, int line, const char* expression) {
  throw oneshot::test::InvariantViolation(std::string(file) + ":" + std::to_string(line) + ": " + expression);
}
}  // namespace

int main(int argc, char** argv) {
  oneshot::host::set_assert_hook(&throw_on_assert);
  ::testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
