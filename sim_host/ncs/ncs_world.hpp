/// @file ncs_world.hpp
/// @brief The engine of a run of study `ncs` (World: kernel, network, CAN buses and their
///        background traffic) and the loops' type aliases and addresses (private to the loops,
///        with ncs_harness.hpp).
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "ncs_live_nodes.hpp"
#include "ncs_loop.hpp"
#include "oneshot/engine/can_traffic.hpp"
#include "oneshot/engine/continuous_plant.hpp"
#include "oneshot/engine/kernel.hpp"
#include "oneshot/engine/network.hpp"
#include "oneshot/host/host_network.hpp"
#include "oneshot/plant_structure.hpp"

namespace oneshot::ncs::loop {

using Board = host::HostNetwork;
using Structure = DenseStructure<kN, kM, kP>;
using Ref = SetpointReference;
using Plant = engine::ContinuousPlant<kN, kM, kP, 1>;
using engine::Duration;
using engine::EventClass;
using engine::HandlerId;
using engine::SimTime;
using InputVec = Vector<double, kM>;
using OutputVec = Vector<double, kP>;

// The live run's addresses (ncs_live.hpp): the frame checks of ncs_live_nodes.hpp name them.
constexpr std::uint8_t kSensor = kLiveSensor;
constexpr std::uint8_t kController = kLiveController;
constexpr std::uint8_t kActuator = kLiveActuator;

/// The engine of a run: kernel, network and the CAN buses with their background traffic;
/// one per run, shared by the loops of a run of several (run_loops()).
struct World {
  /// The engine seeded with `seed`.
  explicit World(std::uint64_t seed) : kernel(seed), net(kernel) {}
  engine::Kernel kernel;   ///< Events.
  engine::Network net;     ///< Nodes, links, buses.
  std::vector<std::pair<std::string, engine::CanBus*>> buses;   ///< Buses by name (built on first use).
  std::vector<std::unique_ptr<engine::CanTraffic>> traffic;     ///< Their background streams.
  SimTime end{0};  ///< The run's end: the latest loop's (the kernel and the background traffic run to it).
};

}  // namespace oneshot::ncs::loop
