/// @file invariant_violation.hpp
/// @brief Exception thrown by the test assert hook.
#pragma once

#include <stdexcept>

namespace oneshot::test {

/// A core invariant (ONESHOT_ASSERT) failed during a test.
class InvariantViolation : public std::logic_error {
 public:
  using std::logic_error::logic_error;
};

}  // namespace oneshot::test
