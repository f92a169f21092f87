/// @file engine_benchmark.cpp
/// @brief The networked-loop benchmark (see engine_benchmark.hpp); also a compact example
///        of wiring firmware nodes, links, a CAN bus and a plant on the engine.
#include "oneshot/sim/engine_benchmark.hpp"

#include <chrono>
#include <memory>

#include "oneshot/engine/can_traffic.hpp"
#include "oneshot/engine/continuous_plant.hpp"
#include "oneshot/engine/network.hpp"
#include "oneshot/node/actuator_node.hpp"
#include "oneshot/node/controller_node.hpp"
#include "oneshot/node/periodic_trigger.hpp"
#include "oneshot/node/sensor_node.hpp"

namespace oneshot::sim {

using namespace oneshot::engine;  // NOLINT: this file is a wiring example of the engine

namespace {

using Board = host::HostNetwork;

/// u = −L y (L stabilises the sampled double integrator for delays below h).
struct Law {
  node::LawResult compute(const node::Message<node::VectorPayload<float, 2>>& m, bool fresh, McuInstant,
                          Vector<float, 1>& u) {
    u[0] = -(0.1F * m.payload.value[0] - 0.4F * m.payload.value[1]);
    return fresh ? node::LawResult::kSend : node::LawResult::kNone;
  }
};

}  // namespace

nlohmann::json networked_loop_benchmark(double simulated_s, std::uint64_t seed) {
  const SimTime end = from_seconds(simulated_s, "benchmark duration");
  const Duration h{50'000'000};
  Kernel k(seed);
  ContinuousPlantConfig<2, 1, 2, 1> cfg;
  cfg.a(0, 1) = -23.8;
  cfg.b(1, 0) = -23.8;
  cfg.c = Matrix<double, 2, 2>::identity();
  cfg.qc = Matrix<double, 2, 2>::identity() * 4e-6;
  cfg.q1c = Matrix<double, 2, 2>::identity();
  cfg.q2c(0, 0) = 1;
  ContinuousPlant<2, 1, 2, 1> plant(cfg, k.stream("process"));
  RandomStream noise = k.stream("measurement");
  Network net(k);
  node::SensorNode<Board, node::PeriodicTrigger<float, 2>, float, 2> sensor(2, node::PeriodicTrigger<float, 2>(1));
  node::ControllerNode<Board, Law, float, 2, 1> ctrl(3, node::ControllerMode::kOnArrival, Law{});
  node::ActuatorNode<Board, float, 1> act(node::ActuatorMode::kOnArrival, Vector<float, 1>{});
  net.add_node(1, "sensor", Duration{0}, nullptr);
  net.add_node(2, "controller", Duration{0}, [&]() { ctrl.on_receive(net.node_clock(2)); });
  net.add_node(3, "actuator", Duration{0}, [&]() {
    act.on_receive();
    Vector<float, 1> u;
    if (act.take_output(u)) {
      plant.advance_to(k.now());
      Vector<double, 1> ud;
      ud[0] = static_cast<double>(u[0]);
      plant.set_input(ud);
    }
  });
  LinkConfig sc;
  sc.name = "sc";
  sc.delay.kind = DelayModel::Kind::kUniform;
  sc.delay.min = from_us(500);
  sc.delay.max = from_us(14'000);
  sc.loss.kind = LossModel::Kind::kBernoulli;
  sc.loss.p = 0.01;
  net.route(1, 2, net.add_link(sc));
  CanBus& bus = net.add_can_bus(CanBusConfig{"can", 500'000, false});
  net.route(2, 3, bus, 0x20);
  std::vector<CanStream> background;
  std::vector<Duration> offsets;
  const std::int64_t periods_us[6] = {1000, 2000, 5000, 10000, 20000, 100000};
  for (std::size_t i = 0; i < 6; ++i) {
    background.push_back({"bg" + std::to_string(i), static_cast<std::uint32_t>(0x10 + 0x20 * i), 8,
                          from_us(periods_us[i]), from_us(periods_us[i] / 10), from_us(periods_us[i])});
    offsets.push_back(from_us(137 * static_cast<std::int64_t>(i)));
  }
  CanTraffic traffic(k, bus, background, offsets, end);
  auto sample_id = std::make_shared<HandlerId>(0);
  *sample_id = k.add_handler("sample", [&, sample_id](std::uint64_t n) {
    plant.advance_to(k.now());
    Vector<float, 2> y;
    const Vector<double, 2> x = plant.output();
    for (std::size_t i = 0; i < 2; ++i) y[i] = static_cast<float>(x[i] + 1e-3 * noise.normal());
    net.run_node(1, [&]() { sensor.on_sample(static_cast<node::SequenceNumber>(n), net.node_clock(1), y); });
    if (k.now() + h < end) k.schedule(k.now() + h, EventClass::kSample, *sample_id, n + 1);
  });
  const HandlerId stop = k.add_handler("end", [&](std::uint64_t) { plant.advance_to(k.now()); });
  k.schedule(SimTime{0}, EventClass::kSample, *sample_id, 0);
  k.schedule(end, EventClass::kEnd, stop);
  const auto t0 = std::chrono::steady_clock::now();
  k.run_until(end);
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const auto events = static_cast<double>(k.events_run());
  return {{"simulated_seconds", simulated_s},
          {"events", k.events_run()},
          {"wall_time_s", wall},
          {"events_per_second", events / wall},
          {"real_time_factor", simulated_s / wall},
          {"bus_frames", bus.statistics().frames},
          {"bus_utilization", to_seconds(bus.statistics().busy) / simulated_s},
          {"commands_applied", act.statistics().applied},
          {"cost", plant.cost().total()}};
}

}  // namespace oneshot::sim
