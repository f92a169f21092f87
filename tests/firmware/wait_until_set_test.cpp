/// @file wait_until_set_test.cpp
/// @brief The tick wait never sleeps through its wake-up, wherever the interrupt lands.
///
/// A model of the Cortex-M core: PRIMASK, one pending interrupt, WFI that returns at once
/// when an interrupt is pending (masked or not) and otherwise sleeps until the next one.
/// The single actuation interrupt is raised just before the k-th core operation, for every
/// k; a WFI entered after the only interrupt has already been handled would sleep forever:
/// the model records it as a lost wake-up.
#include <gtest/gtest.h>

#include "oneshot/app/wait_until_set.hpp"

namespace oneshot::app {
namespace {

struct Core {
  static inline int operations = 0;     // core operations so far
  static inline int raise_at = 0;       // the interrupt arrives before this operation
  static inline bool raised = false;    // it has arrived
  static inline bool pending = false;   // arrived, handler not yet run
  static inline bool masked = false;    // PRIMASK
  static inline bool lost_wakeup = false;
  static inline volatile bool flag = false;

  static void reset(int k) {
    operations = 0;
    raise_at = k;
    raised = pending = masked = lost_wakeup = false;
    flag = false;
  }
  static void handler() {
    pending = false;
    flag = true;  // the actuation handler's g_tick_done = true
  }
  static void deliver() {
    if (pending && !masked) handler();
  }
  /// Before each operation: the interrupt may arrive, and runs at once when unmasked.
  static void step() {
    if (!raised && operations++ == raise_at) {
      raised = true;
      pending = true;
      deliver();
    }
  }
  static void interrupts_off() {
    step();
    masked = true;
  }
  static void interrupts_on() {
    step();
    masked = false;
    deliver();
  }
  static void wait_for_interrupt() {
    step();
    if (pending) return;  // WFI ends at once on a pending interrupt, even while masked
    if (raised) {
      lost_wakeup = true;  // the only interrupt came and went: this WFI never ends
      return;
    }
    raised = true;  // sleep until it arrives
    pending = true;
    deliver();
  }
};

/// The pattern the firmware used before: test, then WFI with interrupts enabled.
void test_then_sleep(const volatile bool& flag) {
  while (!flag) Core::wait_for_interrupt();
}

TEST(WaitUntilSet, NeverSleepsThroughTheWakeUp) {
  for (int k = 0; k < 8; ++k) {
    Core::reset(k);
    wait_until_set<Core>(Core::flag);
    EXPECT_FALSE(Core::lost_wakeup) << "interrupt before operation " << k;
    EXPECT_TRUE(Core::flag);
    EXPECT_FALSE(Core::masked) << "returns with interrupts enabled";
  }
}

TEST(WaitUntilSet, TheModelCatchesTheRaceOfTestThenSleep) {
  // The model is sharp enough: the interrupt landing between the flag test and the WFI of
  // the old loop is a lost wake-up.
  bool lost = false;
  for (int k = 0; k < 4; ++k) {
    Core::reset(k);
    test_then_sleep(Core::flag);
    lost = lost || Core::lost_wakeup;
  }
  EXPECT_TRUE(lost);
}

}  // namespace
}  // namespace oneshot::app
