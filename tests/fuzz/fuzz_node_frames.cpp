/// @file fuzz_node_frames.cpp
/// @brief libFuzzer harness of the network-facing nodes (firmware/node): sequences of raw
///        frames from any source into each node, decode and state machine together.
///
/// Input: records [op (1) | source (1) | length (1) | bytes (length)]; op & 0x7F picks the node:
///   0 sync controller (report)      1 sync sensor (request)     2 sync actuator (command)
///   3 sync actuator timer tick      4 controller node (sample)  5 on-arrival actuator
///   6 PETC arrival (k 4, y 8)       7 threshold buffer (stamp 4, y 8) and a step
///   8 send-on-delta receiver + estimator (node 1, k 4, y 8) and a step
/// The frames of ops 0, 1, 2, 4, 5 get their CRC-16 appended (message.hpp), so the fuzzer
/// reaches the checks behind it; with op bit 7 set they go as given (the CRC check fuzzed).
/// Oracles after every record: no estimate, covariance, command or held value is ever NaN
/// or ±∞, and actuators only apply commands within [u_min, u_max]. After the records, valid
/// traffic resumes (a new epoch from the last bytes): the controllers must command, and
/// the actuator apply, at the latest on the R-th valid frame (kDefaultReacquireFrames, the
/// documented re-acquisition bound of docs/node_validation.md), and on every one after.
#include <cstdint>
#include <cstring>
#include <vector>

#include "fuzz_oracle.hpp"
#include "oneshot/generated/plant_tables.hpp"
#include "oneshot/host/host_network.hpp"
#include "oneshot/node/actuator_node.hpp"
#include "oneshot/node/controller_node.hpp"
#include "oneshot/node/held_measurement.hpp"
#include "oneshot/node/held_measurement_estimator.hpp"
#include "oneshot/node/interlaced_controller.hpp"
#include "oneshot/node/disturbance_observer.hpp"
#include "oneshot/node/petc_controller.hpp"
#include "oneshot/node/sync_actuator_node.hpp"
#include "oneshot/node/sync_controller_node.hpp"
#include "oneshot/node/sync_estimators.hpp"
#include "oneshot/node/sync_sensor_node.hpp"
#include "oneshot/node/threshold_buffer.hpp"
#include "oneshot/table_discretizer.hpp"
#include "support/node_fixtures.hpp"
#include "support/numre_test_model.hpp"

namespace {

using namespace oneshot;
using namespace oneshot::node;
using fuzz::require;
using K = generated::PlantConstants<double>;
using Structure = generated::PlantStructure;
using Disc = TableDiscretizer<K::Format, Structure, double>;
using Est = HalfKalmanEstimator<K::Format, Structure, Disc>;
using Ref = SquareWaveReference<double, 2, 1>;
using Net = host::HostNetwork;
using V1 = Vector<double, 1>;
constexpr std::uint8_t kSensor = 1, kController = 2, kActuator = 3;
constexpr double kU = 1.65;  // actuator range ±kU (the reference board's PWM levels)

using oneshot::test::v1;

double f64(const std::uint8_t* p) {
  double v = 0;
  std::memcpy(&v, p, 8);
  return v;
}

std::uint32_t u32(const std::uint8_t* p) { return std::uint32_t{p[0]} | std::uint32_t{p[1]} << 8 | std::uint32_t{p[2]} << 16 | std::uint32_t{p[3]} << 24; }

void deliver(host::HostNetworkState& to, std::uint8_t from, const std::uint8_t* b, std::size_t n) {
  to.deliver(host::Frame{from, to.address, std::vector<std::uint8_t>(b, b + n)});
}

/// Every node under test, configured as the live run configures them.
struct Nodes {
  Disc disc{K::kTable};
  host::HostNetworkState c_net, s_net, a_net, g_net, o_net;
  SyncControllerNode<Net, Est, Ref, double, 2, 1, 1> ctrl;
  std::uint32_t ctrl_clock_us = 0;  ///< The controller's receive clock (µs).
  SyncSensorNode<Net, double, 1, 1> sensor{kController, 0};
  SyncActuatorNode<Net, double, 1> act{kSensor, V1{}};
  ControllerNode<Net, oneshot::test::EchoLaw, double, 1, 1> generic{kActuator, ControllerMode::kOnArrival, {}};
  ActuatorNode<Net, double, 1> on_arrival{ActuatorMode::kOnArrival, V1{}};
  using Law = InterlacedController<double, 1, 2>;
  PetcController<double, 2, 8, Law, ModelDisturbance<double>> petc;
  ThresholdBuffer<double, 4> buffer;
  HeldMeasurementReceiver<double, 2> rx;
  HeldMeasurementEstimator<double, 2, 1, 2> sod;
  SequenceNumber timer_k = 0, step_k = 0;
  bool seal_ = true;                                ///< Append the CRC to the next frame.
  std::uint8_t sealed_[256 + kCrcBytes] = {};        ///< The frame with its CRC.

  static Est estimator(const Disc& d) {
    Est e(K::kDesign, d, NoiseModel::kExact);
    e.reset(Vector<double, 2>{}, K::kDesign.p0, V1{});
    return e;
  }
  static Matrix<double, 2, 2> eye() { return Matrix<double, 2, 2>::identity(); }
  static Vector<double, 2> two(double v) {
    Vector<double, 2> x;
    x[0] = x[1] = v;
    return x;
  }
  static Law law() {
    InterlacedConfig<double, 1, 2> c{};
    c.ratio = 2;
    return Law(c);
  }
  static constexpr std::uint32_t kNt[2] = {0, 5};  // plain SOD and a time rule of 5 samples

  Nodes()
      : ctrl(kActuator, K::kDesign.l, v1(-kU), v1(kU), estimator(disc), Ref(0.5, 50, Vector<double, 2>{}, V1{})),
        petc(oneshot::test::small_numre_model(), NoiseAccumulation::kSum, law(),
             ModelDisturbance<double>{}, MtmTrigger<double, 1>(0.01, 1e-4, 8, 0), 0.0),
        rx(two(0.05), two(1e-3), kNt, SilencePolicy::kHeld),
        sod(eye(), Matrix<double, 2, 1>{}, eye(), eye()) {
    c_net.address = kController;
    s_net.address = kSensor;
    a_net.address = kActuator;
    g_net.address = kController;
    o_net.address = kActuator;
    ctrl.expect_source(kSensor);
    ctrl.set_measurement_range(v1(-kU), v1(kU));
    ctrl.check_echo_range();
    ctrl.set_tau_range(0, 50'000);
    ctrl.set_period_us(50'000);  // periods without a report predicted over (skip())
    sensor.expect_source(kActuator);
    sensor.set_echo_range(v1(-kU), v1(kU));
    sensor.set_stamp_window(150'000);
    act.expect_source(kController);
    act.set_command_range(v1(-kU), v1(kU));
    generic.expect_source(kSensor);
    on_arrival.expect_source(kController);
    on_arrival.set_command_range(v1(-kU), v1(kU));
    petc.set_measurement_range(-kU, kU);
    sod.reset(Vector<double, 2>{}, eye());
  }

  void check() {
    require(all_finite(ctrl.estimator().estimate()), "sync estimate not finite");
    require(all_finite(ctrl.estimator().filter().covariance()), "sync covariance not finite");
    require(all_finite(ctrl.last_command()) && ctrl.last_command()[0] >= -kU && ctrl.last_command()[0] <= kU,
            "sync command not finite or out of range");
    for (const auto* a : {&act.applied(), &on_arrival.applied()})
      require(all_finite(*a) && (*a)[0] >= -kU && (*a)[0] <= kU, "applied input not finite or out of range");
    require(all_finite(petc.estimator().state()) && all_finite(petc.estimator().covariance()), "NUMRE not finite");
    for (std::size_t l = 0; l < decltype(petc)::kEntries; ++l) require(is_finite(petc.packet()[l]), "PETC packet entry not finite");
    require(all_finite(sod.estimate()) && all_finite(sod.covariance()), "send-on-delta estimate not finite");
    for (const auto& f : g_net.outbox) {
      Message<VectorPayload<double, 1>> m;
      require(decode(f.bytes.data(), f.bytes.size(), m) == FrameStatus::kOk && all_finite(m.payload.value), "controller node sent a non-finite command");
    }
    g_net.outbox.clear();
  }

  /// Delivers the frame (src, b[0..n)) to `net` and runs `on_frame` as the node behind it.
  template <typename F>
  void receive(host::HostNetworkState& net, std::uint8_t src, const std::uint8_t* b, std::size_t n, F&& on_frame) {
    if (seal_ && n + kCrcBytes <= sizeof sealed_) {
      std::memcpy(sealed_, b, n);
      deliver(net, src, sealed_, node::detail::seal(sealed_, n));
    } else {
      deliver(net, src, b, n);
    }
    const host::ScopedHostNetwork cur(net);
    on_frame();
  }

  void run(std::uint8_t op, std::uint8_t src, const std::uint8_t* b, std::size_t n) {
    seal_ = (op & 0x80U) == 0;
    switch ((op & 0x7FU) % 9) {
      case 0:
        receive(c_net, src, b, n, [&] {
          ctrl_clock_us += 50'000U;  // one period per invocation: any stamp may open a gap
          ctrl.on_receive(McuInstant(ctrl_clock_us));
        });
        break;
      case 1:
        receive(s_net, src, b, n, [&] {
          McuInstant at;
          if (sensor.on_receive(McuInstant(n > 4 ? u32(b) : 0U), at)) static_cast<void>(sensor.on_sample(at, v1(0.1)));
        });
        break;
      case 2:
        receive(a_net, src, b, n, [&] { act.on_receive(); });
        break;
      case 3: {
        const host::ScopedHostNetwork cur(a_net);
        ++timer_k;
        act.on_timer(timer_k, McuInstant(timer_k * 50'000U));
        break;
      }
      case 4:
        receive(g_net, src, b, n, [&] { generic.on_receive(McuInstant(0)); });
        break;
      case 5:
        receive(o_net, src, b, n, [&] { on_arrival.on_receive(); });
        break;
      case 6:
        if (n >= 12) static_cast<void>(petc.on_arrival(u32(b), f64(b + 4)));
        break;
      case 7: {
        if (n >= 12) static_cast<void>(buffer.receive(u32(b), f64(b + 4)));
        double y = 0;
        static_cast<void>(buffer.advance(true, y));
        require(is_finite(y), "threshold buffer handed out a non-finite value");
        break;
      }
      case 8: {
        if (n >= 12) static_cast<void>(rx.on_packet(1, u32(b), f64(b + 4)));
        static_cast<void>(sod.predict(V1{}));
        for (std::size_t i = 0; i < 2; ++i) {
          const HeldMeasurement<double> m = rx.measurement(i, step_k);
          if (m.present) static_cast<void>(sod.correct(i, m.z, m.r_bar));
        }
        ++step_k;
        break;
      }
    }
  }

  /// Valid traffic from epoch `base`: R frames must be enough for every node.
  void resume(SequenceNumber base) {
    for (SequenceNumber i = 0; i < kDefaultReacquireFrames + 3; ++i) {
      const SequenceNumber k = base + i;
      const bool must = i + 1 >= kDefaultReacquireFrames;
      std::uint8_t bytes[kMaxMessageBytes];
      SampleReport<double, 1, 1> r;
      r.k = k;
      r.tau_us = 20'000;
      r.y[0] = 0.1;
      c_net.outbox.clear();
      deliver(c_net, kSensor, bytes, encode(r, bytes));
      {
        const host::ScopedHostNetwork cur(c_net);
        ctrl_clock_us += 50'000U;
        ctrl.on_receive(McuInstant(ctrl_clock_us));
      }
      require(!must || (c_net.outbox.size() == 1 && u32(c_net.outbox[0].bytes.data()) == k),
              "sync controller: no command within R valid reports");
      Message<VectorPayload<double, 1>> m;
      m.seq = k;
      m.payload.value = v1(0.25);
      const std::size_t len = encode(m, bytes);
      deliver(g_net, kSensor, bytes, len);
      {
        const host::ScopedHostNetwork cur(g_net);
        generic.on_receive(McuInstant(0));
      }
      require(!must || generic.latest().seq == k, "controller node: sample not used within R valid frames");
      deliver(o_net, kController, bytes, len);
      {
        const host::ScopedHostNetwork cur(o_net);
        on_arrival.on_receive();
      }
      require(!must || (on_arrival.applied_seq() == k && on_arrival.applied()[0] == 0.25),
              "actuator: command not applied within R valid frames");
      check();
    }
  }
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  Nodes nodes;
  std::size_t i = 0;
  while (i + 3 <= size) {
    const std::uint8_t op = data[i], src = data[i + 1];
    std::size_t n = data[i + 2];
    i += 3;
    if (n > size - i) n = size - i;
    nodes.run(op, src, data + i, n);
    nodes.check();
    i += n;
  }
  nodes.resume(size >= 4 ? u32(data + size - 4) : 0U);
  return 0;
}
