/// @file actuator_controller_validation_test.cpp
/// @brief The actuator never applies a non-finite or out-of-range command (holds the last
///        good one and counts), a forged sequence never blocks its buffer, and the generic
///        controller node re-acquires a restarted sensor within R frames (issue 24); every
///        refused frame has the status of its cause (frame_status.hpp), counted by that cause.
#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <limits>

#include "oneshot/host/host_network.hpp"
#include "oneshot/node/actuator_node.hpp"
#include "oneshot/node/controller_node.hpp"
#include "oneshot/node/actuation_sync_messages.hpp"
#include "oneshot/node/sync_actuator_node.hpp"
#include "oneshot/node/sync_sensor_node.hpp"
#include "support/node_fixtures.hpp"

namespace oneshot::node {
namespace {

using V1 = Vector<double, 1>;
constexpr std::uint8_t kSensor = 1;
constexpr std::uint8_t kController = 2;
constexpr std::uint8_t kActuator = 3;
constexpr double kNaNInput = std::numeric_limits<double>::quiet_NaN();

using test::v1;

/// The wire bytes of the one-scalar message (seq, value).
std::vector<std::uint8_t> frame(SequenceNumber seq, double value) {
  Message<VectorPayload<double, 1>> m;
  m.seq = seq;
  m.payload.value = v1(value);
  std::uint8_t bytes[kMaxMessageBytes];
  const std::size_t n = encode(m, bytes);
  return {bytes, bytes + n};
}

/// A node's drop and refusal counters in the order of FrameRefusals.
using Counts = std::array<std::uint32_t, 7>;
Counts counts(const FrameRefusals& r) {
  return {r.malformed, r.stale, r.refused_non_finite, r.refused_out_of_range, r.refused_source, r.refused_sequence, r.reacquired};
}

/// Delivers the command (seq, u) from `from` to `net`.
void deliver(host::HostNetworkState& net, SequenceNumber seq, double u, std::uint8_t from = kController) {
  net.deliver(host::Frame{from, net.address, frame(seq, u)});
}

TEST(ActuatorValidation, TimerModeHoldsTheLastGoodCommand) {
  host::HostNetworkState net;
  net.address = kActuator;
  SyncActuatorNode<host::HostNetwork, double, 1> act(kSensor, v1(0));
  act.set_command_range(v1(-1), v1(1));
  const host::ScopedHostNetwork cur(net);
  deliver(net, 1, 0.5);
  deliver(net, 2, kNaNInput);
  deliver(net, 3, 7.0);   // outside [−1, 1]
  deliver(net, 4, -0.25);
  act.on_receive();
  McuInstant t(0);
  act.on_timer(1, t);
  EXPECT_EQ(act.applied()[0], 0.5);
  act.on_timer(2, t);  // NaN refused: 0.5 held
  EXPECT_EQ(act.applied()[0], 0.5);
  act.on_timer(3, t);  // 7 refused: 0.5 held
  EXPECT_EQ(act.applied()[0], 0.5);
  act.on_timer(4, t);
  EXPECT_EQ(act.applied()[0], -0.25);
  const auto& s = act.statistics();
  EXPECT_EQ(s.refused_non_finite, 1U);
  EXPECT_EQ(s.refused_out_of_range, 1U);
  EXPECT_EQ(s.late, 2U);
}

TEST(ActuatorValidation, ForgedSequenceNeverBlocksABufferSlot) {
  // A command forged for period 3 + 8·1000 (the slot of period 3) arrives first.
  host::HostNetworkState net;
  net.address = kActuator;
  ActuatorNode<host::HostNetwork, double, 1, 8> act(ActuatorMode::kOnTimer, v1(0));
  const host::ScopedHostNetwork cur(net);
  deliver(net, 3 + 8 * 1000, 0.9);
  const double u[4] = {0, 0.1, 0.2, 0.3};
  for (SequenceNumber k = 1; k <= 3; ++k) deliver(net, k, u[k]);
  act.on_receive();
  for (SequenceNumber k = 1; k <= 3; ++k) {
    act.on_timer(k);
    EXPECT_EQ(act.applied()[0], u[k]) << k;
  }
  EXPECT_EQ(act.statistics().late, 0U);
  EXPECT_EQ(act.statistics().refused_sequence, 1U);
}

TEST(ActuatorValidation, OnArrivalModeRefusesNanAndFollowsARestartedController) {
  host::HostNetworkState net;
  net.address = kActuator;
  ActuatorNode<host::HostNetwork, double, 1> act(ActuatorMode::kOnArrival, v1(0));
  act.expect_source(kController);
  const host::ScopedHostNetwork cur(net);
  for (SequenceNumber k = 0; k < 100; ++k) {  // the inbox holds 32 frames: receive as they come
    deliver(net, k, 0.01 * k);
    act.on_receive();
  }
  deliver(net, 100, kNaNInput);
  deliver(net, 101, -std::numeric_limits<double>::infinity());
  deliver(net, 102, 0.5, kSensor);  // not the controller
  act.on_receive();
  EXPECT_EQ(act.applied()[0], 0.01 * 99);
  EXPECT_EQ(act.statistics().refused_non_finite, 2U);
  EXPECT_EQ(act.statistics().refused_source, 1U);
  // One forged far-future command, then the genuine stream goes on.
  deliver(net, 100U + (1U << 31) - (1U << 16), 0.7);
  deliver(net, 100, 0.25);
  act.on_receive();
  EXPECT_EQ(act.applied()[0], 0.25);
  // The controller restarts (sequence from 0): followed again on its R-th command.
  for (SequenceNumber k = 0; k < kDefaultReacquireFrames; ++k) {
    EXPECT_EQ(act.applied_seq(), 100U) << k;
    deliver(net, k, -0.5);
    act.on_receive();
  }
  EXPECT_EQ(act.applied_seq(), kDefaultReacquireFrames - 1);
  EXPECT_EQ(act.applied()[0], -0.5);
  EXPECT_EQ(act.statistics().reacquired, 1U);
}

TEST(ControllerValidation, RestartedSensorReacquiredAndNanRefused) {
  host::HostNetworkState net;
  net.address = kController;
  ControllerNode<host::HostNetwork, test::EchoLaw, double, 1, 1> ctrl(kActuator, ControllerMode::kOnArrival, test::EchoLaw{});
  const host::ScopedHostNetwork cur(net);
  const auto sample = [&](SequenceNumber k, double y) {
    net.deliver(host::Frame{kSensor, kController, frame(k, y)});
    ctrl.on_receive(McuInstant(0));
  };
  for (SequenceNumber k = 0; k < 500; ++k) sample(k, 0.001 * k);
  ASSERT_EQ(net.outbox.size(), 500U);
  sample(500, kNaNInput);
  sample(501U + (1U << 31) - (1U << 16), 1.0);
  EXPECT_EQ(net.outbox.size(), 500U);
  EXPECT_EQ(ctrl.latest().seq, 499U);
  // The sensor restarts: sample indices from 0 again.
  for (SequenceNumber k = 0; k < 10; ++k) sample(k, 0.5);
  EXPECT_EQ(net.outbox.size(), 500U + 10U - (kDefaultReacquireFrames - 1));
  EXPECT_EQ(ctrl.latest().seq, 9U);
  // Per cause: malformed, stale, non-finite, out of range, source, sequence, re-acquired (the
  // restarted sensor's first R − 1 frames are stale against the old base).
  EXPECT_EQ(counts(ctrl.statistics()), (Counts{0, kDefaultReacquireFrames - 1, 1, 0, 0, 1, 1}));
}

TEST(FrameIo, EachRefusedFrameHasTheStatusOfItsCause) {
  host::HostNetworkState net;
  net.address = kController;
  const host::ScopedHostNetwork cur(net);
  ControllerNode<host::HostNetwork, test::EchoLaw, double, 1, 1> ctrl(kActuator, ControllerMode::kOnArrival, test::EchoLaw{});
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
  // Counted per cause: malformed, stale, non-finite, out of range, source, sequence, re-acquired.
  EXPECT_EQ(counts(s), (Counts{1, 1, 1, 1, 2, 1, 0}));
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
  act.on_receive();
  EXPECT_EQ(act.receive_status(), FrameStatus::kOk);  // nothing waited
  deliver(net, 1, 0.5);
  deliver(net, 1, 0.5);  // duplicate: stale
  deliver(net, 2, 3.0);  // out of range
  deliver(net, 3, -0.5);
  act.on_receive();
  EXPECT_EQ(act.receive_status(), FrameStatus::kRefusedOutOfRange);
  EXPECT_EQ(act.applied()[0], -0.5);
  EXPECT_EQ(counts(act.statistics()), (Counts{0, 1, 0, 1, 0, 0, 0}));
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
