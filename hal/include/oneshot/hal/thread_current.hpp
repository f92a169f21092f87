/// @file thread_current.hpp
/// @brief The state a host port's static contract classes act on: one per thread, set by a
///        scope (several simulations run on several threads at once). Host ports only.
#pragma once

#include "oneshot/assert_handler.hpp"

namespace oneshot::hal {

/// Makes `state` this thread's current State for the scope's lifetime; the previous one
/// (or none) is current again afterwards.
template <typename State>
class ScopedCurrent {
 public:
  /// Makes `state` current.
  explicit ScopedCurrent(State& state) : previous_(current_) { current_ = &state; }
  ~ScopedCurrent() { current_ = previous_; }
  ScopedCurrent(const ScopedCurrent&) = delete;
  ScopedCurrent& operator=(const ScopedCurrent&) = delete;

  /// This thread's current State (asserts that one is set).
  static State& current() {
    ONESHOT_ASSERT(current_ != nullptr);
    return *current_;
  }

 private:
  static inline thread_local State* current_ = nullptr;
  State* previous_;
};

}  // namespace oneshot::hal
