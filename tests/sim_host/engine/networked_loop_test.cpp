/// @file networked_loop_test.cpp
/// @brief The firmware's sensor, controller and actuator nodes closing a loop around a
///        continuous plant over the simulated network (links, CAN bus): with zero or
///        constant delays the loop equals the same loop computed directly, bit for bit
///        (the noise-free invariant, here with noise too); losses are counted consistently
///        by links and nodes; stamps carry the sender's clock offset; the run is deterministic;
///        the message log observes only and agrees with the link's counters and delays.
#include <gtest/gtest.h>

#include <vector>

#include "oneshot/engine/continuous_plant.hpp"
#include "oneshot/engine/network.hpp"
#include "oneshot/host/host_network.hpp"
#include "oneshot/node/actuator_node.hpp"
#include "oneshot/node/controller_node.hpp"
#include "oneshot/node/periodic_trigger.hpp"
#include "oneshot/node/sensor_node.hpp"

namespace oneshot::engine {
namespace {

using Plant = ContinuousPlant<2, 1, 2, 1>;
using node::ActuatorMode;
using node::ControllerMode;
using Board = host::HostNetwork;

constexpr Duration kPeriod{50'000'000};
constexpr SimTime kEnd{2'000'000'000};

ContinuousPlantConfig<2, 1, 2, 1> board_plant() {
  ContinuousPlantConfig<2, 1, 2, 1> c;
  c.a(0, 1) = -23.8;
  c.b(1, 0) = -23.8;
  c.c = Matrix<double, 2, 2>::identity();
  c.qc = Matrix<double, 2, 2>::identity() * 4e-6;
  c.q1c = Matrix<double, 2, 2>::identity();
  c.q2c(0, 0) = 1;
  return c;
}

/// u = −L y with a gain that stabilises the sampled double integrator (h = 50 ms) for
/// every constant sensor-to-actuator delay in [0, h).
Matrix<double, 1, 2> gain() {
  const double l[2] = {0.1, -0.4};
  return Matrix<double, 1, 2>(l);
}

/// The board plant on the run's "process" stream, started at x = (0.2, 0).
Plant started_plant(Kernel& k) {
  Plant plant(board_plant(), k.stream("process"));
  Vector<double, 2> x0;
  x0[0] = 0.2;
  plant.set_state(x0);
  return plant;
}

/// Measurement y = C x + v, v ~ N(0, 1e-6 I), from the run's "measurement" stream.
Vector<double, 2> measure(const Plant& plant, RandomStream& rng) {
  Vector<double, 2> y = plant.output();
  for (std::size_t i = 0; i < 2; ++i) y[i] += 1e-3 * rng.normal();
  return y;
}

struct Law {
  Matrix<double, 1, 2> l;
  node::LawResult compute(const node::Message<node::VectorPayload<double, 2>>& m, bool fresh, McuInstant,
                          Vector<double, 1>& u) {
    if (!fresh) return node::LawResult::kNone;
    u = -(l * m.payload.value);
    return node::LawResult::kSend;
  }
};

struct Outcome {
  double cost = 0;
  node::SensorStatistics sensor;
  node::ControllerStatistics controller;
  node::ActuatorStatistics actuator;
  LinkStatistics sc;
  McuInstant last_stamp{};
  std::vector<MessageRecord> messages;  ///< With `record`: every message routed.
};

/// The loop over the network: sensor (address 1) → link "sc" → controller (2) → "ca" or
/// a CAN bus → actuator (3) → plant.
Outcome networked(std::uint64_t seed, LinkConfig sc, LinkConfig ca, bool ca_on_can, bool record = false) {
  Kernel k(seed);
  Plant plant = started_plant(k);
  RandomStream noise = k.stream("measurement");
  Network net(k);
  node::SensorNode<Board, node::PeriodicTrigger<double, 2>, double, 2> sensor(2, node::PeriodicTrigger<double, 2>(1));
  node::ControllerNode<Board, Law, double, 2, 1> ctrl(3, ControllerMode::kOnArrival, Law{gain()});
  node::ActuatorNode<Board, double, 1> act(ActuatorMode::kOnArrival, Vector<double, 1>{});
  net.add_node(1, "sensor", Duration{7'000}, nullptr);
  net.add_node(2, "controller", Duration{0}, [&]() { ctrl.on_receive(net.node_clock(2)); });
  net.add_node(3, "actuator", Duration{0}, [&]() {
    act.on_receive();
    Vector<double, 1> u;
    if (act.take_output(u)) {
      plant.advance_to(k.now());
      plant.set_input(u);
    }
  });
  sc.name = "sc";
  ca.name = "ca";
  if (record) net.record_messages();
  Link& sc_link = net.add_link(sc);
  net.route(1, 2, sc_link);
  if (ca_on_can) {
    net.route(2, 3, net.add_can_bus(CanBusConfig{"can", 500'000, false}), 0x10);
  } else {
    net.route(2, 3, net.add_link(ca));
  }
  auto sample_id = std::make_shared<HandlerId>(0);
  *sample_id = k.add_handler("sample", [&, sample_id](std::uint64_t n) {
    plant.advance_to(k.now());
    const Vector<double, 2> y = measure(plant, noise);
    net.run_node(1, [&]() { sensor.on_sample(static_cast<node::SequenceNumber>(n), net.node_clock(1), y); });
    if (k.now() + kPeriod < kEnd) k.schedule(k.now() + kPeriod, EventClass::kSample, *sample_id, n + 1);
  });
  const HandlerId end = k.add_handler("end", [&](std::uint64_t) { plant.advance_to(k.now()); });
  k.schedule(SimTime{0}, EventClass::kSample, *sample_id, 0);
  k.schedule(kEnd, EventClass::kEnd, end);
  k.run_until(kEnd);
  return {plant.cost().total(), sensor.statistics(), ctrl.statistics(), act.statistics(), sc_link.statistics(),
          ctrl.latest().stamp, net.messages()};
}

/// The same loop computed directly: u = −L y applied `delay` after each sample.
double direct(std::uint64_t seed, Duration delay) {
  Kernel k(seed);
  Plant plant = started_plant(k);
  RandomStream noise = k.stream("measurement");
  std::vector<Vector<double, 1>> pending;
  const HandlerId act = k.add_handler("act", [&](std::uint64_t i) {
    plant.advance_to(k.now());
    plant.set_input(pending[i]);
  });
  auto sample_id = std::make_shared<HandlerId>(0);
  *sample_id = k.add_handler("sample", [&, sample_id](std::uint64_t n) {
    plant.advance_to(k.now());
    const Vector<double, 2> y = measure(plant, noise);
    pending.push_back(-(gain() * y));
    k.schedule(k.now() + delay, EventClass::kDelivery, act, pending.size() - 1);
    if (k.now() + kPeriod < kEnd) k.schedule(k.now() + kPeriod, EventClass::kSample, *sample_id, n + 1);
  });
  const HandlerId end = k.add_handler("end", [&](std::uint64_t) { plant.advance_to(k.now()); });
  k.schedule(SimTime{0}, EventClass::kSample, *sample_id, 0);
  k.schedule(kEnd, EventClass::kEnd, end);
  k.run_until(kEnd);
  return plant.cost().total();
}

LinkConfig constant(std::int64_t us) {
  LinkConfig c;
  c.delay.kind = DelayModel::Kind::kConstant;
  c.delay.constant = from_us(us);
  return c;
}

TEST(NetworkedLoop, ConstantDelaysEqualTheDirectLoopBitForBit) {
  for (const auto& [sc_us, ca_us] : {std::pair{0, 0}, std::pair{3000, 2000}, std::pair{0, 49'000}}) {
    const Outcome o = networked(3, constant(sc_us), constant(ca_us), false);
    EXPECT_EQ(o.cost, direct(3, from_us(sc_us + ca_us))) << sc_us << "+" << ca_us;
    EXPECT_EQ(o.sensor.sends, 40U);
    EXPECT_EQ(o.actuator.applied, 40U);
    EXPECT_LT(o.cost, 0.05);  // the loop is stable
  }
  EXPECT_NE(direct(3, from_us(0)), direct(3, from_us(5000)));  // delay matters
}

TEST(NetworkedLoop, OnACanBusTheDelayIsTheFrameTimes) {
  // An 18-byte command (8-byte header, one double, 2-byte CRC) is two 8-byte frames and a
  // 2-byte one: 2 × 135 + 75 bits (34 + 8s + 13 + ⌊(33 + 8s)/4⌋ for s bytes) at 500 kbit/s.
  const Outcome o = networked(4, constant(1000), LinkConfig{}, true);
  EXPECT_EQ(o.cost, direct(4, from_us(1000 + 690)));
}

TEST(NetworkedLoop, LossesAreCountedConsistentlyAndStampsCarryTheClockOffset) {
  LinkConfig lossy;
  lossy.delay.kind = DelayModel::Kind::kUniform;
  lossy.delay.min = from_us(500);
  lossy.delay.max = from_us(150'000);  // up to three periods: reordering
  lossy.loss.kind = LossModel::Kind::kBernoulli;
  lossy.loss.p = 0.2;
  const Outcome a = networked(5, lossy, constant(1000), false);
  const Outcome b = networked(5, lossy, constant(1000), false);
  EXPECT_EQ(a.cost, b.cost);  // deterministic
  EXPECT_EQ(a.sensor.sends, 40U);
  EXPECT_LT(a.controller.received, 40U);  // some lost
  EXPECT_GT(a.controller.stale, 0U);      // some overtaken (older than the newest): dropped
  EXPECT_EQ(a.controller.sends, a.controller.received - a.controller.stale);
  EXPECT_EQ(a.actuator.applied, a.controller.sends);  // FIFO constant link: every command is newer
  // The last measurement used was stamped by the sensor's clock, 7 µs ahead.
  EXPECT_EQ((a.last_stamp.ticks() - 7) % 50'000, 0U);
  EXPECT_NE(networked(6, lossy, constant(1000), false).cost, a.cost);
}

TEST(NetworkedLoop, TheMessageLogObservesOnly) {
  LinkConfig lossy;
  lossy.delay.kind = DelayModel::Kind::kUniform;
  lossy.delay.min = from_us(500);
  lossy.delay.max = from_us(150'000);
  lossy.loss.kind = LossModel::Kind::kBernoulli;
  lossy.loss.p = 0.2;
  for (const bool can : {false, true}) {
    const Outcome plain = networked(5, lossy, constant(1000), can);
    const Outcome logged = networked(5, lossy, constant(1000), can, true);
    EXPECT_EQ(logged.cost, plain.cost) << can;
    EXPECT_TRUE(plain.messages.empty());
    std::uint64_t sc_sent = 0, sc_lost = 0, ca_sent = 0;
    SimTime last_sent{0};
    for (const MessageRecord& m : logged.messages) {
      EXPECT_GE(m.sent, last_sent);  // in the order sent
      last_sent = m.sent;
      EXPECT_NE(m.lost, m.delivered);  // every link message either lost or with its arrival; the bus delivers all here
      if (m.source == 1) {
        ++sc_sent;
        sc_lost += m.lost;
        if (m.delivered) {
          EXPECT_GE(m.arrival - m.sent, from_us(500));
          EXPECT_LE(m.arrival - m.sent, from_us(150'000));
        }
      } else {
        ++ca_sent;
        EXPECT_EQ(m.destination, 3);
        EXPECT_FALSE(m.lost);
        if (can) {
          EXPECT_GE(m.arrival - m.sent, from_us(540));  // two 135-bit frames at 500 kbit/s, after those queued before
        } else {
          EXPECT_EQ(m.arrival - m.sent, from_us(1000));  // the constant delay
        }
      }
    }
    EXPECT_EQ(sc_sent, logged.sc.sent);
    EXPECT_EQ(sc_lost, logged.sc.lost);
    EXPECT_GT(sc_lost, 0U);
    EXPECT_EQ(ca_sent, logged.controller.sends);
  }
}

}  // namespace
}  // namespace oneshot::engine
