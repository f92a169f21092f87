/// @file udp_network.cpp
/// @brief POSIX UDP port of the network contract (see udp_network.hpp).
#include "oneshot/posix/udp_network.hpp"

#include <arpa/inet.h>
#include <fcntl.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <ctime>
#include <stdexcept>

#include "oneshot/assert_handler.hpp"

namespace oneshot::posix {
namespace {
[[noreturn]] void fail(const char* call) { throw std::runtime_error(std::string(call) + ": " + std::strerror(errno)); }
}  // namespace

bool udp_send(std::uint8_t destination, const std::uint8_t* data, std::size_t size) {
  UdpNetworkState& n = current_udp_network();
  if (size > kUdpMaxPayloadBytes) {
    ++n.refused_sends;
    return false;
  }
  std::uint8_t buf[kUdpHeaderBytes + kUdpMaxPayloadBytes];
  buf[0] = n.address;
  buf[1] = destination;
  if (size != 0) std::memcpy(buf + kUdpHeaderBytes, data, size);
  const ssize_t w = ::sendto(n.fd, buf, kUdpHeaderBytes + size, MSG_DONTWAIT, reinterpret_cast<const sockaddr*>(&n.relay),
                             sizeof n.relay);
  if (w != static_cast<ssize_t>(kUdpHeaderBytes + size)) {
    ++n.refused_sends;
    return false;
  }
  if (n.on_frame) n.on_frame(true, destination, data, size);
  return true;
}

std::size_t udp_receive(std::uint8_t& source, std::uint8_t* data, std::size_t capacity) {
  UdpNetworkState& n = current_udp_network();
  std::uint8_t buf[kUdpHeaderBytes + kUdpMaxPayloadBytes + 1];
  for (;;) {
    const ssize_t r = ::recv(n.fd, buf, sizeof buf, MSG_DONTWAIT);
    if (r < 0) {
      if (errno == EINTR) continue;
      return 0;  // EAGAIN: nothing waiting (other errors: nothing usable either)
    }
    const auto size = static_cast<std::size_t>(r);
    if (size <= kUdpHeaderBytes || size > kUdpHeaderBytes + kUdpMaxPayloadBytes || buf[1] != n.address ||
        size - kUdpHeaderBytes > capacity) {
      ++n.bad_frames;
      continue;
    }
    source = buf[0];
    std::memcpy(data, buf + kUdpHeaderBytes, size - kUdpHeaderBytes);
    if (n.on_frame) n.on_frame(false, source, data, size - kUdpHeaderBytes);
    return size - kUdpHeaderBytes;
  }
}

sockaddr_in loopback(std::uint16_t port) {
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(port);
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  return a;
}

int open_loopback_socket(std::uint16_t port) {
  const int fd = ::socket(AF_INET, SOCK_DGRAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  if (fd < 0) fail("socket");
  const sockaddr_in a = loopback(port);
  if (::bind(fd, reinterpret_cast<const sockaddr*>(&a), sizeof a) != 0) {
    const int e = errno;
    ::close(fd);
    errno = e;
    fail("bind 127.0.0.1");
  }
  return fd;
}

std::uint16_t bound_port(int fd) {
  sockaddr_in a{};
  socklen_t len = sizeof a;
  if (::getsockname(fd, reinterpret_cast<sockaddr*>(&a), &len) != 0) fail("getsockname");
  return ntohs(a.sin_port);
}

void set_nonblocking(int fd) {
  const int flags = ::fcntl(fd, F_GETFL);
  if (flags < 0 || ::fcntl(fd, F_SETFL, flags | O_NONBLOCK) != 0) fail("fcntl O_NONBLOCK");
}

std::int64_t monotonic_ns() {
  timespec ts{};
  ::clock_gettime(CLOCK_MONOTONIC, &ts);
  const std::int64_t sec = ts.tv_sec;
  const std::int64_t nsec = ts.tv_nsec;
  return sec * 1'000'000'000 + nsec;
}

bool wait_readable(int fd, std::int64_t deadline_ns) {
  for (;;) {
    const std::int64_t left = deadline_ns - monotonic_ns();
    pollfd p{fd, POLLIN, 0};
    if (left <= 0) {
      if (fd < 0) return false;
      return ::poll(&p, 1, 0) > 0 && (p.revents & POLLIN) != 0;
    }
    timespec ts{};
    ts.tv_sec = left / 1'000'000'000;
    ts.tv_nsec = left % 1'000'000'000;
    const int r = ::ppoll(fd >= 0 ? &p : nullptr, fd >= 0 ? 1 : 0, &ts, nullptr);
    if (r > 0) return (p.revents & POLLIN) != 0;
    if (r == 0) return false;
    if (errno != EINTR) fail("ppoll");
  }
}

}  // namespace oneshot::posix
