/// @file udp_network.hpp
/// @brief POSIX port of the network contract: frames are UDP datagrams on the loopback
///        interface, sent through a relay (host only, never on an MCU).
///
/// Every frame leaves as one datagram [source address, destination address, payload] to the
/// relay's port; the relay (study code) delays it and forwards it, header included, to the
/// destination's port. Sockets are nonblocking: send() refuses (false, counted) when the
/// kernel buffer is full or the frame too large; receive() returns 0 when nothing waits.
/// Like the host simulation port, the static Net class works on the UdpNetworkState made
/// current on this thread (ScopedUdpNetwork). Time is CLOCK_MONOTONIC, shared by every
/// process of the machine, so all nodes read one synchronized clock.
#pragma once

#include <netinet/in.h>

#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>

#include "oneshot/hal/network_contract.hpp"
#include "oneshot/hal/thread_current.hpp"

namespace oneshot::posix {

/// Bytes of the port's header in front of each payload (source, destination).
inline constexpr std::size_t kUdpHeaderBytes = 2;
/// Largest payload a frame may carry.
inline constexpr std::size_t kUdpMaxPayloadBytes = 256;

/// One node's UDP interface.
struct UdpNetworkState {
  int fd = -1;                      ///< Bound, nonblocking datagram socket.
  std::uint8_t address = 0;         ///< Net::address().
  sockaddr_in relay{};              ///< Where every frame is sent.
  std::uint64_t refused_sends = 0;  ///< Sends refused (too large, buffer full, error).
  std::uint64_t bad_frames = 0;     ///< Datagrams without a valid header, or too long.
  /// Called for every frame sent (send = true) or received, with the peer's address.
  std::function<void(bool send, std::uint8_t peer, const std::uint8_t* data, std::size_t size)> on_frame;
};

/// Makes `state` the current interface of this thread for its lifetime.
using ScopedUdpNetwork = hal::ScopedCurrent<UdpNetworkState>;

/// The current interface of this thread (asserts that one is set).
inline UdpNetworkState& current_udp_network() { return ScopedUdpNetwork::current(); }

/// Sends one frame of the current interface; see network_contract.hpp.
[[nodiscard]] bool udp_send(std::uint8_t destination, const std::uint8_t* data, std::size_t size);
/// Receives one frame of the current interface; see network_contract.hpp.
std::size_t udp_receive(std::uint8_t& source, std::uint8_t* data, std::size_t capacity);

/// The network contract over UDP.
struct UdpNetwork {
  /// Network interface.
  struct Net {
    static std::uint8_t address() { return current_udp_network().address; }
    [[nodiscard]] static bool send(std::uint8_t destination, const std::uint8_t* data, std::size_t size) {
      return udp_send(destination, data, size);
    }
    static std::size_t receive(std::uint8_t& source, std::uint8_t* data, std::size_t capacity) {
      return udp_receive(source, data, capacity);
    }
  };
};

static_assert(hal::kHasNetwork<UdpNetwork>, "the UDP port fulfils the network contract");

/// A nonblocking, close-on-exec UDP socket bound to 127.0.0.1 on a free port (or `port`);
/// std::runtime_error naming the failing call otherwise.
int open_loopback_socket(std::uint16_t port = 0);
/// The port a socket is bound to.
std::uint16_t bound_port(int fd);
/// The address 127.0.0.1:port.
sockaddr_in loopback(std::uint16_t port);
/// Makes `fd` nonblocking (descriptors inherited from a parent).
void set_nonblocking(int fd);

/// CLOCK_MONOTONIC in ns.
std::int64_t monotonic_ns();
/// Waits until `fd` (≥ 0) is readable or CLOCK_MONOTONIC reaches `deadline_ns`; true when
/// readable. fd < 0: only waits. Nanosecond timeout (ppoll), restarted on signals.
bool wait_readable(int fd, std::int64_t deadline_ns);

}  // namespace oneshot::posix
