/// @file host_board.cpp
/// @brief Thread-local current board of the host port.
#include "oneshot/host/host_board.hpp"

#include "oneshot/assert_handler.hpp"

namespace oneshot::host {
namespace {
thread_local HostBoardState* g_current = nullptr;
}  // namespace

ScopedHostBoard::ScopedHostBoard(HostBoardState& state) : previous_(g_current) { g_current = &state; }

ScopedHostBoard::~ScopedHostBoard() { g_current = previous_; }

HostBoardState& current_board() {
  ONESHOT_ASSERT(g_current != nullptr);
  return *g_current;
}

}  // namespace oneshot::host
