/// @file network.hpp
/// @brief The simulated network between nodes: addressed node ports (the host port of the
///        HAL network contract), routes from one address to another over a link or a CAN
///        bus, and the delivery events.
///
/// Node logic (firmware/node/) runs inside run_node(): the node's HostNetworkState is made
/// current (so Board::Net::send/receive reach it), and after the call every frame the node
/// sent is routed: over a Link (loss, delay, FIFO or reordering) or queued on a CanBus
/// with the route's identifier (a message longer than 8 bytes goes as consecutive frames
/// of ≤ 8 bytes with that identifier and arrives with its last one). An arrival is a kDelivery event that puts the frame into
/// the destination's inbox and calls its receive handler inside run_node(). A node's
/// clock reads t + its offset (node_clock()). With a fault spec (set_faults(), before the
/// links are added) every link's frames pass through its LinkFaults (frame_faults.hpp) when
/// sent, and arm_faults() schedules the node restarts through the study's hooks.
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "oneshot/engine/can_bus.hpp"
#include "oneshot/engine/fault_spec.hpp"
#include "oneshot/engine/frame_faults.hpp"
#include "oneshot/engine/kernel.hpp"
#include "oneshot/engine/link.hpp"
#include "oneshot/host/host_network.hpp"

namespace oneshot::engine {

/// A node's attachment to the network.
struct NodePort {
  std::string name;                     ///< For messages.
  host::HostNetworkState interface;     ///< What Board::Net sees inside run_node().
  Duration clock_offset{0};             ///< The node's clock reads t + offset.
  std::function<void()> on_receive;     ///< Called (inside run_node) after each arrival.
};

/// What a route over a CAN bus carried: messages queued and, per delivered message, its
/// delay from the instant it was queued to the end of its last frame (queueing +
/// transmission of every frame).
struct BusRouteStatistics {
  std::uint64_t sent = 0;       ///< Messages queued.
  std::uint64_t delivered = 0;  ///< Messages whose last frame ended.
  Duration min_delay{0};        ///< Smallest delay of a delivered message (0 when none).
  Duration max_delay{0};        ///< Largest.
  Duration total_delay{0};      ///< Sum over the delivered messages.
};

/// One message a route carried, as Network::record_messages() logs it: the instant it was
/// handed to its link or queued on its bus and its fate.
struct MessageRecord {
  std::uint8_t source = 0;       ///< Sending node's address.
  std::uint8_t destination = 0;  ///< Receiving node's address.
  SimTime sent{0};               ///< Handed to the link / queued on the bus.
  SimTime arrival{0};            ///< Arrival (delivered ones; a link's may lie after the run's end: in flight).
  bool lost = false;             ///< Dropped by the link's loss model (arrival meaningless).
  bool delivered = false;        ///< An arrival is known (a link's: not lost; a bus's: its last frame ended).
};

/// Nodes, links, buses and routes of one run.
class Network {
 public:
  /// Network of one run on `kernel`.
  explicit Network(Kernel& kernel);
  Network(const Network&) = delete;
  Network& operator=(const Network&) = delete;

  /// Adds node `address` (unique); `on_receive` runs after each arrival.
  NodePort& add_node(std::uint8_t address, const std::string& name, Duration clock_offset,
                     std::function<void()> on_receive);
  /// Adds a link (its random streams come from the kernel's seed and the link's name).
  Link& add_link(const LinkConfig& config);
  /// Adds a CAN bus.
  CanBus& add_can_bus(const CanBusConfig& config);
  /// Frames from `source` to `destination` travel over `link`.
  void route(std::uint8_t source, std::uint8_t destination, Link& link);
  /// Frames from `source` to `destination` are queued on `bus` with identifier `id`.
  void route(std::uint8_t source, std::uint8_t destination, CanBus& bus, std::uint32_t id);

  /// The statistics of the CAN route from `source` to `destination` (std::invalid_argument
  /// when there is no route over a bus between them).
  const BusRouteStatistics& bus_route_statistics(std::uint8_t source, std::uint8_t destination) const;

  /// Runs `f` as node `address` (its interface current), then routes what it sent.
  void run_node(std::uint8_t address, const std::function<void()>& f);
  /// The node's clock now (wrapping 32-bit µs, with its offset).
  McuInstant node_clock(std::uint8_t address) const;
  /// The node's port.
  NodePort& node(std::uint8_t address);

  /// Faults of `spec` on the links added from now on (std::logic_error after the first link).
  void set_faults(const FaultSpec& spec);
  /// Checks the spec's node names (InputError) and schedules every restart at its instant
  /// (class kEnvironment) through the hook of its node (`restart_hooks` by name). Link names
  /// are the study's to check (check_fault_targets() over every link it may build: a
  /// clause for a link this loop lacks does nothing here).
  void arm_faults(const std::map<std::string, std::function<void()>>& restart_hooks);
  /// Faults injected so far (every link, and the restarts).
  FaultCounters fault_counters() const;

  /// From now on, logs every message routed (observes only: the run is unchanged).
  void record_messages() { record_ = true; }
  /// The messages logged since record_messages(), in the order they were sent.
  const std::vector<MessageRecord>& messages() const { return messages_; }

  /// Frames sent, frames refused because no route exists (a configuration error: counted,
  /// and run_node() throws on the first).
  std::uint64_t frames_sent() const { return frames_sent_; }

 private:
  struct Route {
    Link* link = nullptr;
    LinkFaults* faults = nullptr;
    CanBus* bus = nullptr;
    std::uint32_t id = 0;
    std::size_t bus_stats = 0;  ///< Index in bus_stats_ (bus routes).
  };
  void deliver(std::uint64_t slot);
  void deliver_from_bus(std::uint64_t slot);
  std::uint64_t park(host::Frame frame);

  Kernel& kernel_;
  std::map<std::uint8_t, std::unique_ptr<NodePort>> nodes_;
  std::vector<std::unique_ptr<Link>> links_;
  std::vector<std::unique_ptr<LinkFaults>> link_faults_;  ///< Beside links_ (null: no clause).
  FaultSpec faults_;
  std::uint64_t restarts_ = 0;
  std::vector<std::unique_ptr<CanBus>> buses_;
  std::map<std::pair<std::uint8_t, std::uint8_t>, Route> routes_;
  std::vector<host::Frame> in_flight_;
  std::vector<std::uint64_t> free_slots_;
  std::vector<std::pair<std::size_t, SimTime>> slot_bus_;  ///< Beside in_flight_: bus route, queued at.
  std::vector<BusRouteStatistics> bus_stats_;
  HandlerId deliver_id_ = 0;
  HandlerId bus_deliver_id_ = 0;
  HandlerId fragment_id_ = 0;
  std::uint64_t frames_sent_ = 0;
  bool record_ = false;
  std::vector<MessageRecord> messages_;
  std::vector<std::size_t> slot_record_;  ///< Beside in_flight_ (bus routes, when recording): index in messages_.
};

}  // namespace oneshot::engine
