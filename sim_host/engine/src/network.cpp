/// @file network.cpp
/// @brief The simulated network (see network.hpp).
#include "oneshot/engine/network.hpp"

#include <algorithm>
#include <stdexcept>

namespace oneshot::engine {

Network::Network(Kernel& kernel) : kernel_(kernel) {
  deliver_id_ = kernel_.add_handler("network delivery", [this](std::uint64_t slot) { deliver(slot); });
  fragment_id_ = kernel_.add_handler("network fragment", [](std::uint64_t) {});
  bus_deliver_id_ = kernel_.add_handler("network bus delivery", [this](std::uint64_t slot) { deliver_from_bus(slot); });
}

NodePort& Network::add_node(std::uint8_t address, const std::string& name, Duration clock_offset,
                            std::function<void()> on_receive) {
  if (nodes_.count(address) != 0) throw std::invalid_argument("network: address " + std::to_string(address) + " used twice");
  auto port = std::make_unique<NodePort>();
  port->name = name;
  port->interface.address = address;
  port->clock_offset = clock_offset;
  port->on_receive = std::move(on_receive);
  NodePort& ref = *port;
  nodes_[address] = std::move(port);
  return ref;
}

Link& Network::add_link(const LinkConfig& config) {
  links_.push_back(std::make_unique<Link>(config, kernel_.seed()));
  auto f = std::make_unique<LinkFaults>(faults_, config.name, config.frame, kernel_.seed());
  link_faults_.push_back(f->empty() ? nullptr : std::move(f));
  return *links_.back();
}

void Network::set_faults(const FaultSpec& spec) {
  if (!links_.empty()) throw std::logic_error("network: set_faults() after the first link");
  faults_ = spec;
}

void Network::arm_faults(const std::map<std::string, std::function<void()>>& restart_hooks) {
  std::vector<std::string> nodes;
  for (const auto& [name, hook] : restart_hooks) nodes.push_back(name);
  FaultSpec restarts;
  for (const FaultClause& c : faults_.clauses)
    if (!is_frame_fault(c.kind)) restarts.clauses.push_back(c);
  check_fault_targets(restarts, {}, nodes);
  for (const auto& [name, hook] : restart_hooks) {
    const std::vector<SimTime> at = restart_instants(faults_, name);
    if (at.empty()) continue;
    const HandlerId h = kernel_.add_handler("restart " + name, [this, hook = hook](std::uint64_t) {
      ++restarts_;
      hook();
    });
    for (SimTime t : at) kernel_.schedule(t, EventClass::kEnvironment, h);
  }
}

FaultCounters Network::fault_counters() const {
  FaultCounters c;
  for (const auto& f : link_faults_)
    if (f) c += f->counters();
  c.restart += restarts_;
  return c;
}

CanBus& Network::add_can_bus(const CanBusConfig& config) {
  buses_.push_back(std::make_unique<CanBus>(kernel_, config));
  return *buses_.back();
}

void Network::route(std::uint8_t source, std::uint8_t destination, Link& link) {
  LinkFaults* faults = nullptr;
  for (std::size_t i = 0; i < links_.size(); ++i)
    if (links_[i].get() == &link) faults = link_faults_[i].get();
  routes_[{source, destination}] = Route{&link, faults, nullptr, 0};
}

void Network::route(std::uint8_t source, std::uint8_t destination, CanBus& bus, std::uint32_t id) {
  bus_stats_.emplace_back();
  routes_[{source, destination}] = Route{nullptr, nullptr, &bus, id, bus_stats_.size() - 1};
}

const BusRouteStatistics& Network::bus_route_statistics(std::uint8_t source, std::uint8_t destination) const {
  const auto it = routes_.find({source, destination});
  if (it == routes_.end() || it->second.bus == nullptr) {
    throw std::invalid_argument("network: no CAN route from " + std::to_string(source) + " to " + std::to_string(destination));
  }
  return bus_stats_[it->second.bus_stats];
}

NodePort& Network::node(std::uint8_t address) {
  const auto it = nodes_.find(address);
  if (it == nodes_.end()) throw std::invalid_argument("network: no node at address " + std::to_string(address));
  return *it->second;
}

McuInstant Network::node_clock(std::uint8_t address) const {
  const auto it = nodes_.find(address);
  if (it == nodes_.end()) throw std::invalid_argument("network: no node at address " + std::to_string(address));
  return node_instant<std::uint32_t>(kernel_.now(), it->second->clock_offset);
}

std::uint64_t Network::park(host::Frame frame) {
  if (free_slots_.empty()) {
    in_flight_.push_back(std::move(frame));
    slot_bus_.resize(in_flight_.size());
    return in_flight_.size() - 1;
  }
  const std::uint64_t slot = free_slots_.back();
  free_slots_.pop_back();
  in_flight_[slot] = std::move(frame);
  return slot;
}

void Network::run_node(std::uint8_t address, const std::function<void()>& f) {
  NodePort& port = node(address);
  {
    const host::ScopedHostNetwork current(port.interface);
    f();
  }
  std::vector<host::Frame> sent;
  sent.swap(port.interface.outbox);
  for (host::Frame& frame : sent) {
    ++frames_sent_;
    const auto it = routes_.find({frame.source, frame.destination});
    if (it == routes_.end()) {
      throw std::logic_error("network: node '" + port.name + "' sent to address " + std::to_string(frame.destination) +
                             ", which has no route from it");
    }
    const Route& r = it->second;
    if (r.link != nullptr) {
      std::vector<std::vector<std::uint8_t>> extra;
      if (r.faults != nullptr) r.faults->apply(kernel_.now(), frame.bytes, extra);
      const auto arrival = r.link->transmit(kernel_.now());
      if (record_) {
        MessageRecord m{frame.source, frame.destination, kernel_.now(), arrival.value_or(kernel_.now()), !arrival, arrival.has_value()};
        messages_.push_back(m);
      }
      if (!arrival) continue;
      const std::uint8_t src = frame.source;
      const std::uint8_t dst = frame.destination;
      kernel_.schedule(*arrival, EventClass::kDelivery, deliver_id_, park(std::move(frame)));
      for (auto& bytes : extra) {
        kernel_.schedule(*arrival, EventClass::kDelivery, deliver_id_, park(host::Frame{src, dst, std::move(bytes)}));
      }
    } else {
      // Segmented over CAN frames of ≤ 8 bytes, queued back to back with the route's
      // identifier (FIFO within an identifier): the message arrives with its last frame.
      std::size_t left = frame.bytes.size();
      while (left > 8) {
        r.bus->queue(r.id, 8, fragment_id_, 0);
        left -= 8;
      }
      const std::uint8_t frame_source = frame.source;
      const std::uint8_t frame_destination = frame.destination;
      const std::uint64_t slot = park(std::move(frame));
      slot_bus_[slot] = {r.bus_stats, kernel_.now()};
      ++bus_stats_[r.bus_stats].sent;
      if (record_) {
        slot_record_.resize(in_flight_.size());
        slot_record_[slot] = messages_.size();
        messages_.push_back(MessageRecord{frame_source, frame_destination, kernel_.now(), kernel_.now(), false, false});
      }
      r.bus->queue(r.id, left, bus_deliver_id_, slot);
    }
  }
}

void Network::deliver_from_bus(std::uint64_t slot) {
  const auto [route, queued] = slot_bus_[slot];
  BusRouteStatistics& st = bus_stats_[route];
  const Duration d = kernel_.now() - queued;
  st.min_delay = st.delivered == 0 ? d : std::min(st.min_delay, d);
  st.max_delay = std::max(st.max_delay, d);
  st.total_delay += d;
  ++st.delivered;
  if (record_ && slot < slot_record_.size()) {
    MessageRecord& m = messages_[slot_record_[slot]];
    m.arrival = kernel_.now();
    m.delivered = true;
  }
  deliver(slot);
}

void Network::deliver(std::uint64_t slot) {
  host::Frame frame = std::move(in_flight_[slot]);
  free_slots_.push_back(slot);
  NodePort& port = node(frame.destination);
  port.interface.deliver(std::move(frame));
  if (port.on_receive) run_node(port.interface.address, port.on_receive);
}

}  // namespace oneshot::engine
