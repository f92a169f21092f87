/// @file network.cpp
/// @brief The simulated network (see network.hpp).
#include "oneshot/engine/network.hpp"

#include <stdexcept>

namespace oneshot::engine {

Network::Network(Kernel& kernel) : kernel_(kernel) {
  deliver_id_ = kernel_.add_handler("network delivery", [this](std::uint64_t slot) { deliver(slot); });
  fragment_id_ = kernel_.add_handler("network fragment", [](std::uint64_t) {});
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
  return *links_.back();
}

CanBus& Network::add_can_bus(const CanBusConfig& config) {
  buses_.push_back(std::make_unique<CanBus>(kernel_, config));
  return *buses_.back();
}

void Network::route(std::uint8_t source, std::uint8_t destination, Link& link) {
  routes_[{source, destination}] = Route{&link, nullptr, 0};
}

void Network::route(std::uint8_t source, std::uint8_t destination, CanBus& bus, std::uint32_t id) {
  routes_[{source, destination}] = Route{nullptr, &bus, id};
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
      const auto arrival = r.link->transmit(kernel_.now());
      if (arrival) kernel_.schedule(*arrival, EventClass::kDelivery, deliver_id_, park(std::move(frame)));
    } else {
      // Segmented over CAN frames of ≤ 8 bytes, queued back to back with the route's
      // identifier (FIFO within an identifier): the message arrives with its last frame.
      std::size_t left = frame.bytes.size();
      while (left > 8) {
        r.bus->queue(r.id, 8, fragment_id_, 0);
        left -= 8;
      }
      r.bus->queue(r.id, left, deliver_id_, park(std::move(frame)));
    }
  }
}

void Network::deliver(std::uint64_t slot) {
  host::Frame frame = std::move(in_flight_[slot]);
  free_slots_.push_back(slot);
  NodePort& port = node(frame.destination);
  port.interface.deliver(std::move(frame));
  if (port.on_receive) run_node(port.interface.address, port.on_receive);
}

}  // namespace oneshot::engine
