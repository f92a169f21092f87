/// @file pil_protocol_test.cpp
/// @brief PIL requests decode only at their exact length and known values.
#include <gtest/gtest.h>

#include "oneshot/app/pil_protocol.hpp"

namespace oneshot::app::pil {
namespace {

Frame sample_frame(std::size_t p) {
  Frame f;
  Writer w(f);
  w.u(41'000, 4);
  w.u(50'000, 4);
  for (std::size_t o = 0; o < p; ++o) w.s(-2300 - static_cast<std::int32_t>(o), 2);
  for (std::size_t o = 0; o < p; ++o) w.s(2048 + static_cast<std::int32_t>(o), 2);
  return f;
}

TEST(PilProtocol, ASampleDecodesAtItsExactLengthOnly) {
  Frame f = sample_frame(2);
  SampleRequest<2> s;
  ASSERT_TRUE(decode(f, s));
  EXPECT_EQ(s.now_us, 41'000U);
  EXPECT_EQ(s.next_actuation_us, 50'000U);
  EXPECT_EQ(s.adc[1], -2301);
  EXPECT_EQ(s.setpoint[1], 2049);
  // Every truncation, and one byte too many, is refused and leaves the request untouched.
  for (std::size_t len = 0; len <= SampleRequest<2>::kLength + 1; ++len) {
    if (len == SampleRequest<2>::kLength) continue;
    Frame g = f;
    g.length = len;
    SampleRequest<2> t;
    t.now_us = 7;
    EXPECT_FALSE(decode(g, t)) << len;
    EXPECT_EQ(t.now_us, 7U) << len;
  }
  SampleRequest<1> one;
  EXPECT_FALSE(decode(f, one));  // a two-output sample is not a one-output sample
}

TEST(PilProtocol, AConfigNeedsAKnownApproachAndNoiseModel) {
  Frame f;
  Writer w(f);
  w.u(4, 1);
  w.u(1, 1);
  w.u(2000, 2);
  ConfigRequest<1> c;
  ASSERT_TRUE(decode(f, c));
  EXPECT_EQ(c.approach, 4);
  EXPECT_TRUE(c.exact_noise);
  EXPECT_EQ(c.codes[0], 2000);
  Frame bad = f;
  bad.payload[0] = kMaxApproach;  // the generated C job
  EXPECT_TRUE(decode(bad, c));
  EXPECT_EQ(c.approach, kMaxApproach);
  bad.payload[0] = kMaxApproach + 1;  // nothing beyond it
  EXPECT_FALSE(decode(bad, c));
  bad = f;
  bad.payload[1] = 2;
  EXPECT_FALSE(decode(bad, c));
  bad = f;
  bad.length = 3;
  EXPECT_FALSE(decode(bad, c));
}

TEST(PilProtocol, ATickIsFourBytes) {
  Frame f;
  Writer w(f);
  w.u(123'456, 4);
  TickRequest t;
  ASSERT_TRUE(decode(f, t));
  EXPECT_EQ(t.now_us, 123'456U);
  f.length = 3;
  EXPECT_FALSE(decode(f, t));
}

TEST(PilProtocol, FramesSurviveTheWireAndCorruptionIsDropped) {
  Frame f = sample_frame(1);
  f.type = Type::kSample;
  f.seq = 0x7E7D;  // both special bytes in the sequence number
  std::uint8_t wire[2 * (kMaxPayload + 5) + 2];
  const std::size_t n = encode(f, wire);
  Decoder d;
  bool got = false;
  for (std::size_t i = 0; i < n; ++i) got = d.feed(wire[i]);
  ASSERT_TRUE(got);
  EXPECT_EQ(d.frame().seq, f.seq);
  EXPECT_EQ(d.frame().length, f.length);
  wire[n / 2] ^= 0x01;
  Decoder e;
  got = false;
  for (std::size_t i = 0; i < n; ++i) got = got || e.feed(wire[i]);
  EXPECT_FALSE(got);
  EXPECT_EQ(e.dropped(), 1U);
}

}  // namespace
}  // namespace oneshot::app::pil
