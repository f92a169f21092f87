/// @file node_logic_test.cpp
/// @brief The node logic of firmware/node: wire form and its CRC, serial sequence numbers, the trigger
///        rules' equations, the command buffer, and the nodes' bookkeeping on the host port.
#include <gtest/gtest.h>

#include "oneshot/crc16.hpp"
#include "oneshot/fixed_point.hpp"
#include "oneshot/host/host_network.hpp"
#include "oneshot/node/actuation_sync_messages.hpp"
#include "oneshot/node/actuator_node.hpp"
#include "oneshot/node/command_buffer.hpp"
#include "oneshot/node/controller_node.hpp"
#include "oneshot/node/mtm_trigger.hpp"
#include "oneshot/node/periodic_trigger.hpp"
#include "oneshot/node/send_on_delta_trigger.hpp"
#include "oneshot/node/sensor_node.hpp"
#include "support/node_fixtures.hpp"

namespace oneshot::node {
namespace {

using V1 = Vector<double, 1>;

using test::v1;

template <typename S, std::size_t P>
void round_trip(const Vector<S, P>& value) {
  Message<VectorPayload<S, P>> m;
  m.seq = 0xFFFFFFFEU;
  m.stamp = McuInstant(0x89ABCDEFU);
  m.payload.value = value;
  std::uint8_t bytes[kMaxMessageBytes];
  const std::size_t n = encode(m, bytes);
  EXPECT_EQ(n, (encoded_size<S, P>()));
  EXPECT_EQ(bytes[0], 0xFE);  // little-endian
  Message<VectorPayload<S, P>> back;
  ASSERT_EQ(decode(bytes, n, back), FrameStatus::kOk);
  EXPECT_EQ(back.seq, m.seq);
  EXPECT_EQ(back.stamp, m.stamp);
  for (std::size_t i = 0; i < P; ++i) EXPECT_EQ(ScalarTraits<S>::to_double(back.payload.value[i]), ScalarTraits<S>::to_double(value[i]));
  EXPECT_EQ(decode(bytes, n - 1, back), FrameStatus::kMalformed);  // a short frame is refused
}

TEST(Message, RoundTripsEveryScalarExactly) {
  Vector<float, 3> f;
  f[0] = -1.5e-7F;
  f[1] = 3.25F;
  f[2] = -0.0F;
  round_trip(f);
  Vector<double, 2> d;
  d[0] = 0.1;
  d[1] = -1e300;
  round_trip(d);
  using Q = Fixed<std::int32_t, 29>;
  Vector<Q, 2> q;
  q[0] = Q::from_raw(-123456789);
  q[1] = Q::from_raw(2147483647);
  round_trip(q);
}

TEST(Crc16, GivesTheCcittFalseCheckValue) {
  // The catalogue's check value of CRC-16/CCITT-FALSE: CRC("123456789") = 0x29B1.
  static constexpr std::uint8_t kCheck[] = {'1', '2', '3', '4', '5', '6', '7', '8', '9'};
  static_assert(crc16_ccitt_false(kCheck, sizeof kCheck) == 0x29B1, "CRC-16/CCITT-FALSE check value");
  EXPECT_EQ(crc16_ccitt_false(kCheck, sizeof kCheck), 0x29B1);
  EXPECT_EQ(crc16_ccitt_false(kCheck, 0), kCrc16Init);
}

TEST(Crc16, TheNibbleTableStepIsTheBitwiseStepForEveryRegister) {
  // The bitwise definition (8 shift/XOR steps per byte, MSB first) against the table form.
  const auto bitwise = [](std::uint16_t crc, std::uint8_t byte) {
    unsigned c = crc ^ (static_cast<unsigned>(byte) << 8U);
    for (int i = 0; i < 8; ++i) c = ((c & 0x8000U) != 0U ? (c << 1U) ^ 0x1021U : c << 1U) & 0xFFFFU;
    return static_cast<std::uint16_t>(c);
  };
  for (unsigned r = 0; r < 0x10000U; ++r)
    for (const std::uint8_t b : {std::uint8_t{0x00}, std::uint8_t{0x0F}, std::uint8_t{0x5A}, std::uint8_t{0xF0}, std::uint8_t{0xFF}})
      ASSERT_EQ(crc16_update(static_cast<std::uint16_t>(r), b), bitwise(static_cast<std::uint16_t>(r), b)) << r << " " << +b;
}

/// Encodes `m`; checks the trailer is the CRC of the bytes before it (low byte first), then
/// that every frame with `flips` (1 or 2) distinct bits inverted decodes as kCorrupt and
/// leaves the message untouched. Returns the frames tried.
template <typename Msg>
std::size_t expect_flips_corrupt(const Msg& m, int flips) {
  std::uint8_t bytes[kMaxMessageBytes];
  const std::size_t n = encode(m, bytes);
  const std::uint16_t crc = crc16_ccitt_false(bytes, n - kCrcBytes);
  EXPECT_EQ(bytes[n - 2], crc & 0xFFU);
  EXPECT_EQ(bytes[n - 1], crc >> 8);
  Msg back{};
  EXPECT_EQ(decode(bytes, n, back), FrameStatus::kOk);
  std::size_t tried = 0;
  std::size_t wrong = 0;
  const std::size_t bits = 8 * n;
  for (std::size_t a = 0; a < bits; ++a) {
    for (std::size_t b = flips == 2 ? a + 1 : a; b < (flips == 2 ? bits : a + 1); ++b) {
      std::uint8_t f[kMaxMessageBytes];
      for (std::size_t i = 0; i < n; ++i) f[i] = bytes[i];
      f[a / 8] = static_cast<std::uint8_t>(f[a / 8] ^ (1U << (a % 8)));
      if (flips == 2) f[b / 8] = static_cast<std::uint8_t>(f[b / 8] ^ (1U << (b % 8)));
      Msg got{};
      if (decode(f, n, got) != FrameStatus::kCorrupt) ++wrong;
      ++tried;
    }
  }
  EXPECT_EQ(wrong, 0U) << wrong << " of " << tried << " frames with " << flips << " flipped bits not refused as corrupt";
  return tried;
}

TEST(Message, EverySingleBitFlipOfEveryMessageTypeIsRefusedAsCorrupt) {
  Message<VectorPayload<double, 2>> md;
  md.seq = 77;
  md.stamp = McuInstant(123456U);
  md.payload.value[0] = 0.25;
  md.payload.value[1] = -3.0;
  EXPECT_EQ(expect_flips_corrupt(md, 1), (8 * encoded_size<double, 2>()));
  Message<VectorPayload<float, 3>> mf;
  mf.seq = 0xFFFFFFFFU;
  mf.payload.value[1] = 1.5F;
  EXPECT_EQ(expect_flips_corrupt(mf, 1), (8 * encoded_size<float, 3>()));
  using Q = Fixed<std::int32_t, 29>;
  Message<VectorPayload<Q, 1>> mq;
  mq.seq = 5;
  mq.payload.value[0] = Q::from_raw(-42);
  EXPECT_EQ(expect_flips_corrupt(mq, 1), (8 * encoded_size<Q, 1>()));
  ActuationRequest<double, 1> req;
  req.k = 9;
  req.t_k = McuInstant(1000U);
  req.u_applied[0] = 0.5;
  EXPECT_EQ(expect_flips_corrupt(req, 1), (8 * request_size<double, 1>()));
  SampleReport<double, 2, 1> rep;
  rep.k = 9;
  rep.t_s = McuInstant(990U);
  rep.tau_us = -10;
  rep.y[0] = 1.0;
  rep.y[1] = -2.0;
  rep.u_applied[0] = 0.5;
  EXPECT_EQ(expect_flips_corrupt(rep, 1), (8 * report_size<double, 2, 1>()));
}

TEST(Message, EveryDoubleBitFlipOfAReportIsRefusedAsCorrupt) {
  SampleReport<double, 2, 1> rep;  // the longest frame of the loops: 38 bytes, 304 bits
  rep.k = 123;
  rep.t_s = McuInstant(0xDEADBEEFU);
  rep.tau_us = 1500;
  rep.y[0] = 0.125;
  rep.y[1] = -7.5;
  rep.u_applied[0] = 2.0;
  const std::size_t bits = 8 * report_size<double, 2, 1>();
  EXPECT_EQ(expect_flips_corrupt(rep, 2), bits * (bits - 1) / 2);
}

TEST(Message, SequenceNumbersCompareAcrossTheWrap) {
  EXPECT_TRUE(seq_newer(1, 0));
  EXPECT_FALSE(seq_newer(0, 0));
  EXPECT_TRUE(seq_newer(2, 0xFFFFFFFFU));
  EXPECT_FALSE(seq_newer(0xFFFFFFFFU, 2));
}

TEST(Triggers, SendOnDeltaAndItsTimeRule) {
  // δy = 0.5, n_t = 3: (2a) |y − y_last| > δy strictly, (2b) k − k_last ≥ n_t.
  SendOnDeltaTrigger<double, 1> plain(v1(0.5), 0);
  SendOnDeltaTrigger<double, 1> modified(v1(0.5), 3);
  const double ys[] = {0.0, 0.4, 0.5, 0.51, 0.6, 0.6, 0.6, 0.6, -0.2};
  const SendCause plain_expected[] = {SendCause::kFirst, SendCause::kNone, SendCause::kNone, SendCause::kDelta,
                                      SendCause::kNone,  SendCause::kNone, SendCause::kNone, SendCause::kNone,
                                      SendCause::kDelta};
  const SendCause modified_expected[] = {SendCause::kFirst, SendCause::kNone, SendCause::kNone, SendCause::kDelta,
                                         SendCause::kNone,  SendCause::kNone, SendCause::kTime, SendCause::kNone,
                                         SendCause::kDelta};
  for (SequenceNumber k = 0; k < 9; ++k) {
    const SendCause a = plain.evaluate(k, v1(ys[k]));
    const SendCause b = modified.evaluate(k, v1(ys[k]));
    EXPECT_EQ(a, plain_expected[k]) << k;
    EXPECT_EQ(b, modified_expected[k]) << k;
    if (a != SendCause::kNone) plain.on_sent(k, v1(ys[k]));
    if (b != SendCause::kNone) modified.on_sent(k, v1(ys[k]));
  }
}

TEST(Triggers, MixedThresholdSafetyAndReferenceChange) {
  // (ȳ − y)² > σ y² + δ with σ = 0.01, δ = 1e-4; safety after 5; reference send 2 after a change.
  MtmTrigger<double, 1> t(0.01, 1e-4, 5, 2);
  EXPECT_EQ(t.evaluate(0, v1(1.0)), SendCause::kFirst);
  t.on_sent(0, v1(1.0));
  EXPECT_EQ(t.evaluate(1, v1(1.1)), SendCause::kNone);   // 0.01 ≤ 0.01·1.21 + 1e-4
  EXPECT_EQ(t.evaluate(1, v1(1.12)), SendCause::kDelta);  // 0.0144 > 0.0126
  EXPECT_EQ(t.evaluate(4, v1(1.0)), SendCause::kNone);
  EXPECT_EQ(t.evaluate(5, v1(1.0)), SendCause::kTime);  // k − k_last ≥ k_max
  t.on_sent(5, v1(1.0));
  t.notify_reference_change(6);
  EXPECT_EQ(t.evaluate(7, v1(1.0)), SendCause::kNone);
  EXPECT_EQ(t.evaluate(8, v1(1.0)), SendCause::kReference);
  t.on_sent(8, v1(1.0));
  EXPECT_EQ(t.evaluate(10, v1(1.0)), SendCause::kNone);  // the reference send is done
  PeriodicTrigger<double, 1> every3(3);
  EXPECT_EQ(every3.evaluate(6, v1(0)), SendCause::kPeriodic);
  EXPECT_EQ(every3.evaluate(7, v1(0)), SendCause::kNone);
}

TEST(CommandBuffer, KeyedBySequenceNumberNewerKept) {
  CommandBuffer<double, 1, 4> b;
  EXPECT_EQ(b.store(10, v1(1)), FrameStatus::kOk);
  EXPECT_EQ(b.store(11, v1(2)), FrameStatus::kOk);
  V1 u;
  EXPECT_TRUE(b.find(10, u));
  EXPECT_EQ(u[0], 1);
  EXPECT_FALSE(b.find(14, u));    // same slot as 10, other number
  EXPECT_EQ(b.store(14, v1(5)), FrameStatus::kOk);  // newer replaces 10
  EXPECT_FALSE(b.find(10, u));
  EXPECT_EQ(b.store(10, v1(9)), FrameStatus::kStale);  // older than the slot's 14: kept out
  EXPECT_TRUE(b.find(14, u));
  EXPECT_EQ(u[0], 5);
}

TEST(Nodes, SensorControllerActuatorOnTheHostPort) {
  host::HostNetworkState s_if;
  s_if.address = 1;
  host::HostNetworkState c_if;
  c_if.address = 2;
  host::HostNetworkState a_if;
  a_if.address = 3;
  SensorNode<host::HostNetwork, PeriodicTrigger<double, 1>, double, 1> sensor(2, PeriodicTrigger<double, 1>(1));
  ControllerNode<host::HostNetwork, test::EchoLaw, double, 1, 1> ctrl(3, ControllerMode::kOnArrival, test::EchoLaw{});
  ActuatorNode<host::HostNetwork, double, 1> act(ActuatorMode::kOnTimer, v1(-1));
  const auto hop = [](host::HostNetworkState& from, host::HostNetworkState& to, std::size_t index) {
    to.deliver(from.outbox.at(index));
  };
  {
    const host::ScopedHostNetwork cur(s_if);
    for (SequenceNumber k = 0; k < 3; ++k) sensor.on_sample(k, McuInstant(100 * k), v1(0.5 * k));
  }
  ASSERT_EQ(s_if.outbox.size(), 3U);
  // Arrive out of order: 2, 0, 1 (0 and 1 are stale after 2).
  hop(s_if, c_if, 2);
  hop(s_if, c_if, 0);
  hop(s_if, c_if, 1);
  c_if.deliver(host::Frame{1, 2, {1, 2, 3}});  // malformed
  {
    const host::ScopedHostNetwork cur(c_if);
    ctrl.on_receive(McuInstant(999));
  }
  EXPECT_EQ(ctrl.statistics().received, 3U);
  EXPECT_EQ(ctrl.statistics().stale, 2U);
  EXPECT_EQ(ctrl.statistics().malformed, 1U);
  ASSERT_EQ(c_if.outbox.size(), 1U);
  hop(c_if, a_if, 0);
  {
    const host::ScopedHostNetwork cur(a_if);
    act.on_receive();
    act.on_timer(1);  // nothing for period 1: hold −1, late
    V1 u;
    EXPECT_FALSE(act.take_output(u));
    EXPECT_EQ(act.applied()[0], -1);
    act.on_timer(2);  // the command computed from sample 2
    EXPECT_TRUE(act.take_output(u));
    EXPECT_EQ(u[0], 1.0);
  }
  EXPECT_EQ(act.statistics().late, 1U);
  EXPECT_EQ(act.statistics().applied, 1U);
}

}  // namespace
}  // namespace oneshot::node
