/// @file frame_io_test.cpp
/// @brief Every refused frame has the status of its cause, counted by that cause, and the
///        nodes' shared glue reports the worst status of a batch and the result of a send.
#include <gtest/gtest.h>

#include <cstdint>
#include <limits>
#include <vector>

#include "oneshot/host/host_network.hpp"
#include "oneshot/node/actuation_sync_messages.hpp"
#include "oneshot/node/actuator_node.hpp"
#include "oneshot/node/controller_node.hpp"
#include "oneshot/node/sync_sensor_node.hpp"

namespace oneshot::node {
namespace {

using V1 = Vector<double, 1>;
constexpr std::uint8_t kSensor = 1;
constexpr std::uint8_t kController = 2;
constexpr std::uint8_t kActuator = 3;

V1 v1(double x) {
  V1 v;
  v[0] = x;
  return v;
}

/// The wire bytes of the one-scalar message (seq, y).
std::vector<std::uint8_t> frame(SequenceNumber seq, double y) {
  Message<VectorPayload<double, 1>> m;
  m.seq = seq;
  m.payload.value = v1(y);
  std::uint8_t bytes[kMaxMessageBytes];
  const std::size_t n = encode(m, bytes);
  return {bytes, bytes + n};
}

struct Echo {
  LawResult compute(const Message<VectorPayload<double, 1>>& m, bool fresh, McuInstant, V1& u) {
    u = m.payload.value;
    return fresh ? LawResult::kSend : LawResult::kNone;
  }
};

TEST(FrameIo, EachRefusedFrameHasTheStatusOfItsCause) {
  host::HostNetworkState net;
  net.address = kController;
  const host::ScopedHostNetwork cur(net);
  ControllerNode<host::HostNetwork, Echo, double, 1, 1> ctrl(kActuator, ControllerMode::kOnArrival, Echo{});
  ctrl.expect_source(kSensor);
  ctrl.set_measurement_range(v1(-1), v1(1));
  ctrl.set_sequence_window(16, 3);
  const McuInstant now(0);
  const auto offer = [&](std::uint8_t source, const std::vector<std::uint8_t>& b) {
    return ctrl.on_frame(source, b.data(), b.size(), now);
  };
  EXPECT_EQ(offer(kSensor, frame(10, 0.5)), FrameStatus::kOk);
  std::vector<std::uint8_t> short_frame = frame(11, 0.5);
  short_frame.pop_back();
  EXPECT_EQ(offer(kSensor, short_frame), FrameStatus::kMalformed);
  EXPECT_EQ(offer(kActuator, frame(11, 0.5)), FrameStatus::kRefusedSource);
  EXPECT_EQ(offer(kSensor, frame(11, std::numeric_limits<double>::quiet_NaN())), FrameStatus::kRefusedNonFinite);
  EXPECT_EQ(offer(kSensor, frame(11, 1.5)), FrameStatus::kRefusedOutOfRange);
  EXPECT_EQ(offer(kSensor, frame(10, 0.5)), FrameStatus::kStale);
  EXPECT_EQ(offer(kSensor, frame(10 + 17, 0.5)), FrameStatus::kRefusedSequence);
  EXPECT_EQ(offer(kSensor, frame(11, 0.25)), FrameStatus::kOk);
  // The checks run in order: a wrong sender with a NaN payload is refused for its sender.
  EXPECT_EQ(offer(kActuator, frame(12, std::numeric_limits<double>::quiet_NaN())), FrameStatus::kRefusedSource);
  const ControllerStatistics& s = ctrl.statistics();
  EXPECT_EQ(s.malformed, 1U);
  EXPECT_EQ(s.refused_source, 2U);
  EXPECT_EQ(s.refused_non_finite, 1U);
  EXPECT_EQ(s.refused_out_of_range, 1U);
  EXPECT_EQ(s.stale, 1U);
  EXPECT_EQ(s.refused_sequence, 1U);
  EXPECT_EQ(s.received, 8U);  // every frame that decoded
  EXPECT_EQ(s.sends, 2U);     // one command per accepted measurement
  EXPECT_EQ(ctrl.last_send(), SendResult::kSent);
  EXPECT_EQ(ctrl.latest().seq, 11U);
}

TEST(FrameIo, OnReceiveKeepsTheWorstStatusOfItsFrames) {
  host::HostNetworkState net;
  net.address = kActuator;
  const host::ScopedHostNetwork cur(net);
  ActuatorNode<host::HostNetwork, double, 1> act(ActuatorMode::kOnArrival, v1(0));
  act.set_command_range(v1(-1), v1(1));
  const auto deliver = [&](SequenceNumber seq, double u) {
    net.deliver(host::Frame{kController, kActuator, frame(seq, u)});
  };
  act.on_receive();
  EXPECT_EQ(act.receive_status(), FrameStatus::kOk);  // nothing waited
  deliver(1, 0.5);
  deliver(1, 0.5);  // duplicate: stale
  deliver(2, 3.0);  // out of range
  deliver(3, -0.5);
  act.on_receive();
  EXPECT_EQ(act.receive_status(), FrameStatus::kRefusedOutOfRange);
  EXPECT_EQ(act.applied()[0], -0.5);
  EXPECT_EQ(act.statistics().stale, 1U);
  EXPECT_EQ(act.statistics().refused_out_of_range, 1U);
  // A timer-mode actuator refuses a command beyond its Slots window as a sequence jump.
  ActuatorNode<host::HostNetwork, double, 1, 4> timed(ActuatorMode::kOnTimer, v1(0));
  const std::vector<std::uint8_t> far = frame(5, 0.1);
  EXPECT_EQ(timed.on_frame(kController, far.data(), far.size()), FrameStatus::kRefusedSequence);
  const std::vector<std::uint8_t> near = frame(4, 0.1);
  EXPECT_EQ(timed.on_frame(kController, near.data(), near.size()), FrameStatus::kOk);
}

TEST(FrameIo, SyncSensorReportsWhatBecameOfItsSample) {
  host::HostNetworkState net;
  net.address = kSensor;
  const host::ScopedHostNetwork cur(net);
  SyncSensorNode<host::HostNetwork, double, 1, 1> sensor(kController, 0);
  EXPECT_EQ(sensor.on_sample(McuInstant(0), v1(0.1)), ReportResult::kNoRequest);
  ActuationRequest<double, 1> r;
  r.k = 1;
  r.t_k = McuInstant(100);
  r.u_applied = v1(0.0);
  std::uint8_t bytes[kMaxMessageBytes];
  const std::size_t n = encode(r, bytes);
  EXPECT_EQ(sensor.on_frame(kActuator, bytes, n, McuInstant(0)), FrameStatus::kOk);
  EXPECT_EQ(sensor.on_sample(McuInstant(10), v1(0.1)), ReportResult::kSent);
  EXPECT_EQ(sensor.statistics().sends, 1U);
  EXPECT_EQ(sensor.on_frame(kActuator, bytes, n - 1, McuInstant(0)), FrameStatus::kMalformed);
}

}  // namespace
}  // namespace oneshot::node
