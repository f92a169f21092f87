/// @file host_network.hpp
/// @brief Host port of the network contract: frames go to and come from the simulator.
///
/// Like the host board, the static Net class works on the HostNetworkState made current
/// on this thread (ScopedHostNetwork), one per node, so nodes of many runs can execute on
/// many threads. The simulator makes a node's state current around each call into the
/// node, collects its outbox afterwards and hands it to the links, and puts delivered
/// frames into its inbox before calling the node's receive handler.
#pragma once

#include <cstddef>
#include <cstdint>
#include <deque>
#include <vector>

#include "oneshot/hal/network_contract.hpp"
#include "oneshot/hal/thread_current.hpp"

namespace oneshot::host {

/// A frame on the emulated network.
struct Frame {
  std::uint8_t source = 0;           ///< Sender's address.
  std::uint8_t destination = 0;      ///< Receiver's address.
  std::vector<std::uint8_t> bytes;   ///< Contents.
};

/// The emulated network interface of one node.
struct HostNetworkState {
  std::uint8_t address = 0;               ///< Net::address().
  std::size_t max_frame_bytes = 64;       ///< Larger sends are refused.
  std::size_t inbox_capacity = 32;        ///< Frames held before new arrivals are dropped.
  std::deque<Frame> inbox;                ///< Delivered, not yet received.
  std::vector<Frame> outbox;              ///< Sent since the simulator last collected them.
  std::uint64_t refused_sends = 0;        ///< Sends refused (too large).
  std::uint64_t dropped_arrivals = 0;     ///< Arrivals dropped (inbox full).
  std::uint64_t truncated_receives = 0;   ///< Frames longer than the receive buffer (dropped).

  /// A delivery from the network (dropped and counted when the inbox is full).
  void deliver(Frame f) {
    if (inbox.size() >= inbox_capacity) {
      ++dropped_arrivals;
      return;
    }
    inbox.push_back(std::move(f));
  }
};

/// Makes `state` the current network interface of this thread for its lifetime.
using ScopedHostNetwork = hal::ScopedCurrent<HostNetworkState>;

/// The current network interface of this thread (asserts that one is set).
inline HostNetworkState& current_network() { return ScopedHostNetwork::current(); }

/// The network contract on the host.
struct HostNetwork {
  /// Network interface.
  struct Net {
    static std::uint8_t address() { return current_network().address; }
    [[nodiscard]] static bool send(std::uint8_t destination, const std::uint8_t* data, std::size_t size) {
      HostNetworkState& n = current_network();
      if (size > n.max_frame_bytes) {
        ++n.refused_sends;
        return false;
      }
      n.outbox.push_back(Frame{n.address, destination, std::vector<std::uint8_t>(data, data + size)});
      return true;
    }
    static std::size_t receive(std::uint8_t& source, std::uint8_t* data, std::size_t capacity) {
      HostNetworkState& n = current_network();
      while (!n.inbox.empty()) {
        Frame f = std::move(n.inbox.front());
        n.inbox.pop_front();
        if (f.bytes.size() > capacity || f.bytes.empty()) {
          ++n.truncated_receives;
          continue;
        }
        source = f.source;
        for (std::size_t i = 0; i < f.bytes.size(); ++i) data[i] = f.bytes[i];
        return f.bytes.size();
      }
      return 0;
    }
  };
};

static_assert(hal::kHasNetwork<HostNetwork>, "the host port fulfils the network contract");

}  // namespace oneshot::host
