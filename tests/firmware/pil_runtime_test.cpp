/// @file pil_runtime_test.cpp
/// @brief The MCU PIL runtime over a fake SoC: the requests every image answers alike, the
///        image's own requests handed over with the reply begun, a retransmission answered from
///        the last reply without running the request again, the fault and invariant reports,
///        and byte reception through the receive interrupt.
#include <gtest/gtest.h>

#include <cstdint>
#include <deque>
#include <string>
#include <vector>

#include "oneshot/app/pil_runtime.hpp"

/// The firmware's stack probe (startup.cpp on the MCU): a fixed figure here.
extern "C" std::uint32_t oneshot_stack_peak_bytes() { return 1234; }

namespace oneshot::app::pil {
namespace {

/// Bytes sent and bytes waiting in the receiver, seen by the fake UART.
struct Wire {
  static inline std::vector<std::uint8_t> sent;
  static inline std::deque<std::uint8_t> incoming;
  static inline int wakeups_armed = 0;
};

struct FakeUart {
  static void init() {}
  static void put(std::uint8_t b) { Wire::sent.push_back(b); }
  template <typename Sink>
  static void drain(Sink&& sink) {
    while (!Wire::incoming.empty()) {
      sink(Wire::incoming.front());
      Wire::incoming.pop_front();
    }
  }
};
struct FakeWakeup {
  static void init() {}
  static void arm() { ++Wire::wakeups_armed; }
  static void disarm() {}
  static void acknowledge() {}
};
struct FakeCpu {
  static void interrupts_off() {}
  static void interrupts_on() {}
  static void wait_for_interrupt() {}
};
using Runtime = PilRuntime<FakeUart, FakeWakeup, FakeCpu>;

constexpr ImageInfo kInfo{1, 0, 2, 12, 1, 1};

std::vector<std::uint8_t> encoded(const Frame& f) {
  std::uint8_t out[Runtime::kMaxEncoded];
  return {out, out + encode(f, out)};
}

/// Every frame sent since the last call, decoded.
std::vector<Frame> sent_frames() {
  std::vector<Frame> frames;
  Decoder d;
  for (const std::uint8_t b : Wire::sent) {
    if (d.feed(b)) frames.push_back(d.frame());
  }
  Wire::sent.clear();
  return frames;
}

Frame request(Type type, std::uint16_t seq, std::vector<std::uint8_t> payload = {}) {
  Frame q;
  q.type = type;
  q.seq = seq;
  Writer w(q);
  for (const std::uint8_t b : payload) w.u(b, 1);
  return q;
}

/// An image's dispatch: counts its calls and answers with one byte.
struct CountingHandler {
  int calls = 0;
  void operator()(const Frame& q, Frame& r) {
    ++calls;
    EXPECT_EQ(r.seq, q.seq);  // begun by the runtime
    EXPECT_EQ(r.type, reply_type(q.type));
    EXPECT_EQ(r.length, 0U);
    Writer w(r);
    w.u(0xA5, 1);
  }
};

/// Feeds a whole request; true when it was answered.
bool feed(Runtime::Session& s, const Frame& q, CountingHandler& h) {
  bool answered = false;
  for (const std::uint8_t b : encoded(q)) answered = s.feed(b, kInfo, h) || answered;
  return answered;
}

TEST(PilRuntime, AnswersHelloCalibrateAndEchoItselfAndRefusesAMalformedHello) {
  Wire::sent.clear();
  Runtime::Session s;
  CountingHandler h;
  ASSERT_TRUE(feed(s, request(Type::kHello, 1), h));
  ASSERT_TRUE(feed(s, request(Type::kEcho, 2, {0x7E, 0x7D, 3}), h));
  ASSERT_TRUE(feed(s, request(Type::kCalibrate, 3), h));
  ASSERT_TRUE(feed(s, request(Type::kHello, 4, {0}), h));
  EXPECT_EQ(h.calls, 0);
  const std::vector<Frame> r = sent_frames();
  ASSERT_EQ(r.size(), 4U);
  Reader hello(r[0]);
  EXPECT_EQ(r[0].type, reply_type(Type::kHello));
  EXPECT_EQ(r[0].seq, 1U);
  EXPECT_EQ(hello.u(1), kProtocolVersion);
  EXPECT_EQ(hello.u(1), 1U);  // target
  EXPECT_EQ(hello.u(1), 0U);  // format
  EXPECT_EQ(hello.u(1), 2U);  // discretizer
  EXPECT_EQ(hello.u(1), 12U);
  EXPECT_EQ(hello.u(1), 1U);
  EXPECT_EQ(hello.u(1), 1U);
  EXPECT_EQ(hello.u(2), 1234U);  // stack peak
  EXPECT_FALSE(hello.bad());
  EXPECT_EQ(r[0].length, 9U);
  ASSERT_EQ(r[1].length, 3U);
  EXPECT_EQ(r[1].payload[0], 0x7E);
  EXPECT_EQ(r[1].payload[2], 3);
  EXPECT_EQ(r[2].type, reply_type(Type::kCalibrate));
  EXPECT_EQ(r[2].length, 0U);
  EXPECT_EQ(r[3].type, Type::kFault);
  EXPECT_EQ(Reader(r[3]).u(4), kFaultMalformedRequest);
}

TEST(PilRuntime, ARetransmittedRequestIsAnsweredAgainButRunOnce) {
  Wire::sent.clear();
  Runtime::Session s;
  CountingHandler h;
  const Frame q = request(static_cast<Type>(0x03), 7, {1, 2});
  ASSERT_TRUE(feed(s, q, h));
  ASSERT_TRUE(feed(s, q, h));  // the reply was lost: same sequence number
  EXPECT_EQ(h.calls, 1);
  ASSERT_TRUE(feed(s, request(static_cast<Type>(0x03), 8, {1, 2}), h));
  EXPECT_EQ(h.calls, 2);
  ASSERT_TRUE(feed(s, request(static_cast<Type>(0x04), 8), h));  // same number, other request
  EXPECT_EQ(h.calls, 3);
  const std::vector<Frame> r = sent_frames();
  ASSERT_EQ(r.size(), 4U);
  for (const Frame& f : r) {
    ASSERT_EQ(f.length, 1U);
    EXPECT_EQ(f.payload[0], 0xA5);
  }
  EXPECT_EQ(r[0].seq, 7U);
  EXPECT_EQ(r[1].seq, 7U);
  EXPECT_EQ(r[3].type, reply_type(static_cast<Type>(0x04)));
  EXPECT_EQ(s.dropped(), 0U);
}

TEST(PilRuntime, FaultAndInvariantReportsNameTheCauseAndFitThePayload) {
  Frame f;
  write_fault(f, kFaultHard);
  EXPECT_EQ(f.type, Type::kFault);
  ASSERT_EQ(f.length, 4U);
  EXPECT_EQ(Reader(f).u(4), kFaultHard);
  write_assert(f, "a.cpp", 42);
  Reader in(f);
  EXPECT_EQ(in.u(4), 42U);
  EXPECT_EQ(in.u(1), static_cast<std::uint32_t>('a'));
  EXPECT_EQ(f.length, 4U + 5U);
  // A path longer than the payload is cut at the payload, never beyond it.
  const std::string long_path(3 * kMaxPayload, 'x');
  write_assert(f, long_path.c_str(), 7);
  EXPECT_EQ(f.length, kMaxPayload);
  EXPECT_EQ(f.payload[kMaxPayload - 1], 'x');
}

TEST(PilRuntime, BytesArriveInOrderThroughTheReceiveInterrupt) {
  Wire::incoming = {1, 2};
  Runtime::on_uart_rx();  // the interrupt: both into the ring
  Wire::incoming = {3};   // the next byte wakes the loop from its sleep
  Wire::wakeups_armed = 0;
  EXPECT_EQ(Runtime::next_byte(), 1U);
  EXPECT_EQ(Runtime::next_byte(), 2U);
  EXPECT_EQ(Wire::wakeups_armed, 0);  // bytes were waiting: no sleep
  EXPECT_EQ(Runtime::next_byte(), 3U);
  EXPECT_EQ(Wire::wakeups_armed, 1);  // the ring was empty: slept once
}

}  // namespace
}  // namespace oneshot::app::pil
