/// @file host_network.cpp
/// @brief Thread-local current network interface of the host port.
#include "oneshot/host/host_network.hpp"

#include "oneshot/assert_handler.hpp"

namespace oneshot::host {
namespace {
thread_local HostNetworkState* g_current = nullptr;
}  // namespace

ScopedHostNetwork::ScopedHostNetwork(HostNetworkState& state) : previous_(g_current) { g_current = &state; }

ScopedHostNetwork::~ScopedHostNetwork() { g_current = previous_; }

HostNetworkState& current_network() {
  ONESHOT_ASSERT(g_current != nullptr);
  return *g_current;
}

}  // namespace oneshot::host
