/// @file actuator_controller_validation_test.cpp
/// @brief The actuator never applies a non-finite or out-of-range command (holds the last
///        good one and counts), a forged sequence never blocks its buffer, and the generic
///        controller node re-acquires a restarted sensor within R frames (issue 24).
#include <gtest/gtest.h>

#include <cstdint>
#include <limits>

#include "oneshot/host/host_network.hpp"
#include "oneshot/node/actuator_node.hpp"
#include "oneshot/node/controller_node.hpp"
#include "oneshot/node/sync_actuator_node.hpp"
#include "support/node_fixtures.hpp"

namespace oneshot::node {
namespace {

using V1 = Vector<double, 1>;
constexpr std::uint8_t kSensor = 1;
constexpr std::uint8_t kController = 2;
constexpr std::uint8_t kActuator = 3;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

using test::v1;

/// Delivers the command (seq, u) from `from` to `net`.
void deliver(host::HostNetworkState& net, SequenceNumber seq, double u, std::uint8_t from = kController) {
  Message<VectorPayload<double, 1>> c;
  c.seq = seq;
  c.payload.value = v1(u);
  std::uint8_t bytes[kMaxMessageBytes];
  const std::size_t n = encode(c, bytes);
  net.deliver(host::Frame{from, net.address, std::vector<std::uint8_t>(bytes, bytes + n)});
}

TEST(ActuatorValidation, TimerModeHoldsTheLastGoodCommand) {
  host::HostNetworkState net;
  net.address = kActuator;
  SyncActuatorNode<host::HostNetwork, double, 1> act(kSensor, v1(0));
  act.set_command_range(v1(-1), v1(1));
  const host::ScopedHostNetwork cur(net);
  deliver(net, 1, 0.5);
  deliver(net, 2, kNaN);
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
  deliver(net, 100, kNaN);
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
    Message<VectorPayload<double, 1>> m;
    m.seq = k;
    m.payload.value = v1(y);
    std::uint8_t bytes[kMaxMessageBytes];
    const std::size_t n = encode(m, bytes);
    net.deliver(host::Frame{kSensor, kController, std::vector<std::uint8_t>(bytes, bytes + n)});
    ctrl.on_receive(McuInstant(0));
  };
  for (SequenceNumber k = 0; k < 500; ++k) sample(k, 0.001 * k);
  ASSERT_EQ(net.outbox.size(), 500U);
  sample(500, kNaN);
  sample(501U + (1U << 31) - (1U << 16), 1.0);
  EXPECT_EQ(net.outbox.size(), 500U);
  EXPECT_EQ(ctrl.latest().seq, 499U);
  // The sensor restarts: sample indices from 0 again.
  for (SequenceNumber k = 0; k < 10; ++k) sample(k, 0.5);
  EXPECT_EQ(net.outbox.size(), 500U + 10U - (kDefaultReacquireFrames - 1));
  EXPECT_EQ(ctrl.latest().seq, 9U);
  const auto& s = ctrl.statistics();
  EXPECT_EQ(s.refused_non_finite, 1U);
  EXPECT_EQ(s.refused_sequence, 1U);
  EXPECT_EQ(s.reacquired, 1U);
}

}  // namespace
}  // namespace oneshot::node
