/// @file threshold_buffer_test.cpp
/// @brief The threshold ring: window, over-delay, duplicates, reordering, future stamps, wrap.
#include <gtest/gtest.h>

#include <limits>

#include "oneshot/node/threshold_buffer.hpp"

namespace oneshot::node {
namespace {

TEST(ThresholdBuffer, NonFiniteValuesAreRefusedAndCounted) {
  // A NaN in the window never reaches the filter: refused, the slot stays free for the genuine copy.
  ThresholdBuffer<double, 3> b;
  double y = 0;
  for (int i = 0; i < 3; ++i) static_cast<void>(b.advance(false, y));
  EXPECT_EQ(b.receive(1, std::numeric_limits<double>::quiet_NaN()), ArrivalVerdict::kNonFinite);
  EXPECT_EQ(b.receive(1, std::numeric_limits<double>::infinity()), ArrivalVerdict::kNonFinite);
  EXPECT_EQ(b.receive(1, 0.5), ArrivalVerdict::kStored);
  EXPECT_TRUE(b.holds(1, y));
  EXPECT_EQ(y, 0.5);
  EXPECT_EQ(b.counts().refused_non_finite, 2U);
}

TEST(ThresholdBuffer, WindowReorderDuplicatesOverDelayFuture) {
  ThresholdBuffer<int, 3> b;  // before step 0: window empty, everything is future
  EXPECT_EQ(b.receive(0, 10), ArrivalVerdict::kFuture);
  int y = 0;
  EXPECT_FALSE(b.advance(false, y));  // step 0
  EXPECT_FALSE(b.advance(false, y));  // step 1
  EXPECT_FALSE(b.advance(false, y));  // step 2 → next is 3: window [0, 2]
  EXPECT_EQ(b.receive(2, 12), ArrivalVerdict::kStored);   // out of order: 2 before 0
  EXPECT_EQ(b.receive(0, 10), ArrivalVerdict::kStored);
  EXPECT_EQ(b.receive(0, 99), ArrivalVerdict::kDuplicate);  // first copy stays
  EXPECT_EQ(b.receive(3, 13), ArrivalVerdict::kFuture);
  EXPECT_TRUE(b.holds(2, y));
  EXPECT_EQ(y, 12);
  EXPECT_FALSE(b.holds(1, y));
  EXPECT_TRUE(b.advance(true, y));  // step 3 takes n = 0
  EXPECT_EQ(y, 10);
  EXPECT_EQ(b.receive(0, 10), ArrivalVerdict::kOverDelayed);  // now older than the window [1, 3]
  EXPECT_EQ(b.receive(1, 11), ArrivalVerdict::kStored);       // just in time for step 4
  EXPECT_EQ(b.receive(3, 13), ArrivalVerdict::kStored);       // reuses slot of 0
  EXPECT_TRUE(b.advance(true, y));  // step 4 takes 1
  EXPECT_EQ(y, 11);
  EXPECT_TRUE(b.advance(true, y));  // step 5 takes 2
  EXPECT_EQ(y, 12);
  EXPECT_TRUE(b.advance(true, y));  // step 6 takes 3
  EXPECT_EQ(y, 13);
  EXPECT_FALSE(b.advance(true, y));  // step 7: 4 never came
  const auto& c = b.counts();
  EXPECT_EQ(c.stored, 4U);
  EXPECT_EQ(c.duplicates, 1U);
  EXPECT_EQ(c.over_delayed, 1U);
  EXPECT_EQ(c.future, 2U);
  EXPECT_EQ(c.taken, 4U);
  EXPECT_EQ(c.missed, 1U);
}

TEST(ThresholdBuffer, SerialNumbersAcrossTheWrap) {
  ThresholdBuffer<int, 4> b(0xFFFFFFFEU);  // two steps before the counter wraps
  int y = 0;
  static_cast<void>(b.advance(true, y));   // step 2^32 − 2
  EXPECT_EQ(b.receive(0xFFFFFFFEU, 5), ArrivalVerdict::kStored);
  static_cast<void>(b.advance(true, y));   // step 2^32 − 1
  static_cast<void>(b.advance(true, y));   // step 0 (wrapped)
  EXPECT_EQ(b.receive(0xFFFFFFFFU, 6), ArrivalVerdict::kStored);
  EXPECT_EQ(b.receive(0, 7), ArrivalVerdict::kStored);
  EXPECT_EQ(b.receive(1, 8), ArrivalVerdict::kFuture);
  EXPECT_TRUE(b.holds(0xFFFFFFFEU, y));
  EXPECT_EQ(y, 5);
  EXPECT_EQ(b.oldest(), 0xFFFFFFFDU);
}

}  // namespace
}  // namespace oneshot::node
