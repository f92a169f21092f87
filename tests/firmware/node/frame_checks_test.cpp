/// @file frame_checks_test.cpp
/// @brief The core's finiteness test and the node frame checks (frame_checks.hpp): the
///        sequence window, re-acquisition of a new epoch after R frames, the expected
///        source and the value range, each refusal counted under its cause.
#include <gtest/gtest.h>

#include <cstdint>
#include <limits>

#include "oneshot/finite.hpp"
#include "oneshot/fixed_point.hpp"
#include "oneshot/node/frame_checks.hpp"

namespace oneshot::node {
namespace {

TEST(Finite, FloatDoubleAndFixed) {
  EXPECT_TRUE(is_finite(0.0F));
  EXPECT_TRUE(is_finite(-std::numeric_limits<float>::max()));
  EXPECT_TRUE(is_finite(std::numeric_limits<double>::denorm_min()));
  EXPECT_FALSE(is_finite(std::numeric_limits<float>::quiet_NaN()));
  EXPECT_FALSE(is_finite(-std::numeric_limits<float>::infinity()));
  EXPECT_FALSE(is_finite(std::numeric_limits<double>::quiet_NaN()));
  EXPECT_FALSE(is_finite(std::numeric_limits<double>::infinity()));
  EXPECT_TRUE(is_finite(Fixed<std::int32_t, 29>::from_raw(-2147483647 - 1)));
  Vector<double, 3> v{};
  EXPECT_TRUE(all_finite(v));
  v[2] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(all_finite(v));
}

TEST(SequenceGate, WindowStaleAndJump) {
  SequenceGate g(10, 3);
  EXPECT_EQ(g.offer(100), SequenceVerdict::kAccepted);  // the first frame sets the base
  EXPECT_EQ(g.offer(101), SequenceVerdict::kAccepted);
  EXPECT_EQ(g.offer(111), SequenceVerdict::kAccepted);  // d = W
  EXPECT_EQ(g.offer(111), SequenceVerdict::kStale);     // duplicate
  EXPECT_EQ(g.offer(105), SequenceVerdict::kStale);     // reordered
  EXPECT_EQ(g.offer(122), SequenceVerdict::kJump);      // d = W + 1
  EXPECT_EQ(g.last(), 111U);
  // Across the wrap.
  SequenceGate w(10, 3);
  EXPECT_EQ(w.offer(0xFFFFFFFEU), SequenceVerdict::kAccepted);
  EXPECT_EQ(w.offer(3), SequenceVerdict::kAccepted);
}

TEST(SequenceGate, OneForgedFrameNeverMovesTheBase) {
  // The attack: one frame 2^31 − 2^16 ahead, then the genuine stream goes on.
  SequenceGate g;
  for (SequenceNumber k = 0; k < 50; ++k) ASSERT_TRUE(accepted(g.offer(k)));
  EXPECT_EQ(g.offer(49U + (1U << 31) - (1U << 16)), SequenceVerdict::kJump);
  for (SequenceNumber k = 50; k < 100; ++k) EXPECT_EQ(g.offer(k), SequenceVerdict::kAccepted) << k;
  // Forged frames interleaved with the genuine stream (even R − 1 consistent ones) never win.
  for (SequenceNumber k = 100; k < 200; ++k) {
    EXPECT_FALSE(accepted(g.offer(k + 0x40000000U))) << k;
    EXPECT_EQ(g.offer(k), SequenceVerdict::kAccepted) << k;
  }
}

TEST(SequenceGate, RestartedPeerIsReacquiredOnItsRthFrame) {
  for (std::uint32_t r : {2U, 3U, 5U}) {
    SequenceGate g(kDefaultSequenceWindow, r);
    for (SequenceNumber k = 0; k < 1000; ++k) ASSERT_TRUE(accepted(g.offer(k)));
    // The peer restarts: sequence numbers from 0 again (all stale against 999).
    for (SequenceNumber k = 0; k + 1 < r; ++k) EXPECT_EQ(g.offer(k), SequenceVerdict::kStale) << r << " " << k;
    EXPECT_EQ(g.offer(r - 1), SequenceVerdict::kReacquired) << r;
    EXPECT_EQ(g.offer(r), SequenceVerdict::kAccepted) << r;
    EXPECT_EQ(g.last(), r);
  }
  // A jump far ahead that goes on (a peer that lost its sequence state) is followed too.
  SequenceGate g(10, 3);
  ASSERT_TRUE(accepted(g.offer(5)));
  EXPECT_EQ(g.offer(5000), SequenceVerdict::kJump);
  EXPECT_EQ(g.offer(5001), SequenceVerdict::kJump);
  EXPECT_EQ(g.offer(5003), SequenceVerdict::kReacquired);  // a gap within W keeps the run
}

TEST(FrameChecks, SourceAndRangeCountedByCause) {
  FrameRefusals r;
  ExpectedSource any;
  EXPECT_EQ(count_frame(any.check(7), r), FrameStatus::kOk);
  ExpectedSource src;
  src.set(2);
  EXPECT_EQ(count_frame(src.check(2), r), FrameStatus::kOk);
  EXPECT_EQ(count_frame(src.check(3), r), FrameStatus::kRefusedSource);
  EXPECT_EQ(r.refused_source, 1U);
  Vector<double, 2> lo, hi, v;
  lo[0] = -1;
  lo[1] = 0;
  hi[0] = 1;
  hi[1] = 5;
  const ValueRange<double, 2> range(lo, hi);
  v[0] = 1;
  v[1] = 0;
  EXPECT_EQ(count_frame(check_payload(v, range), r), FrameStatus::kOk);  // bounds are inside
  v[1] = 5.000001;
  EXPECT_EQ(count_frame(check_payload(v, range), r), FrameStatus::kRefusedOutOfRange);
  EXPECT_EQ(r.refused_out_of_range, 1U);
  v[1] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(count_frame(check_payload(v, range), r), FrameStatus::kRefusedNonFinite);
  // Unchecked range: still finite only.
  EXPECT_EQ(count_frame(check_payload(v, ValueRange<double, 2>{}), r), FrameStatus::kRefusedNonFinite);
  EXPECT_EQ(r.refused_non_finite, 2U);
  EXPECT_EQ(r.refused_out_of_range, 1U);
}

TEST(FrameChecks, StatusOrderedBySeverityAndCountedPerCause) {
  // The first check that fails names the frame; the worst of several frames is the most severe.
  EXPECT_EQ(then_check(FrameStatus::kRefusedSource, [] { return FrameStatus::kRefusedNonFinite; }),
            FrameStatus::kRefusedSource);
  EXPECT_EQ(then_check(FrameStatus::kOk, [] { return FrameStatus::kStale; }), FrameStatus::kStale);
  EXPECT_EQ(worst_of(FrameStatus::kStale, FrameStatus::kReacquired), FrameStatus::kStale);
  EXPECT_EQ(worst_of(FrameStatus::kRefusedOutOfRange, FrameStatus::kMalformed), FrameStatus::kMalformed);
  EXPECT_EQ(worst_of(FrameStatus::kCorrupt, FrameStatus::kRefusedSource), FrameStatus::kCorrupt);
  EXPECT_EQ(worst_of(FrameStatus::kCorrupt, FrameStatus::kMalformed), FrameStatus::kMalformed);
  EXPECT_FALSE(accepted(FrameStatus::kCorrupt));
  EXPECT_TRUE(accepted(FrameStatus::kReacquired));
  EXPECT_FALSE(accepted(FrameStatus::kStale));
  EXPECT_EQ(frame_status(SequenceVerdict::kJump), FrameStatus::kRefusedSequence);
  // Every cause has its own counter, and kOk counts nothing.
  FrameRefusals r;
  for (const FrameStatus s : {FrameStatus::kOk, FrameStatus::kReacquired, FrameStatus::kStale, FrameStatus::kRefusedSequence,
                              FrameStatus::kRefusedOutOfRange, FrameStatus::kRefusedNonFinite, FrameStatus::kRefusedSource,
                              FrameStatus::kCorrupt, FrameStatus::kMalformed})
    EXPECT_EQ(count_frame(s, r), s) << to_string(s);
  EXPECT_EQ(r.reacquired + r.stale + r.refused_sequence + r.refused_out_of_range + r.refused_non_finite + r.refused_source +
                r.corrupt + r.malformed,
            8U);
  EXPECT_EQ(r.malformed, 1U);
  EXPECT_EQ(r.corrupt, 1U);
  EXPECT_EQ(r.stale, 1U);
}

}  // namespace
}  // namespace oneshot::node
