/// @file termination_cleanup.cpp
/// @brief Signal handlers ending child groups and removing temporary files.
#include "oneshot/util/termination_cleanup.hpp"

#include <array>
#include <atomic>
#include <climits>
#include <csignal>
#include <cstring>
#include <mutex>
#include <unistd.h>

namespace oneshot::util {
namespace {

constexpr std::size_t kSlots = 64;

/// Process groups to kill; 0 marks a free slot.
std::array<std::atomic<int>, kSlots> g_groups{};

/// Temporary files; a slot is read by the handler only in state kReady.
enum SlotState : int { kFree = 0, kFilling = 1, kReady = 2 };
struct TempSlot {
  std::atomic<int> state{kFree};
  char path[PATH_MAX] = {};
};
std::array<TempSlot, kSlots> g_temp{};

constexpr std::array<int, 3> kSignals = {SIGINT, SIGTERM, SIGHUP};

extern "C" void on_termination_signal(int sig) {
  for (auto& g : g_groups) {
    const int pgid = g.load(std::memory_order_acquire);
    if (pgid > 0) ::kill(-pgid, SIGKILL);
  }
  for (TempSlot& t : g_temp) {
    if (t.state.load(std::memory_order_acquire) == kReady) ::unlink(t.path);
  }
  // SA_RESETHAND restored the default action: the re-raised signal ends the program
  // when this handler returns, with the usual status.
  ::raise(sig);
}

}  // namespace

void install_termination_handlers() {
  static std::once_flag once;
  std::call_once(once, [] {
    for (int sig : kSignals) {
      struct sigaction old {};
      if (::sigaction(sig, nullptr, &old) == 0 && old.sa_handler == SIG_IGN) continue;  // nohup and friends
      struct sigaction sa {};
      sa.sa_handler = on_termination_signal;
      sigemptyset(&sa.sa_mask);
      for (int other : kSignals) sigaddset(&sa.sa_mask, other);
      sa.sa_flags = static_cast<int>(SA_RESETHAND);
      ::sigaction(sig, &sa, nullptr);
    }
  });
}

bool register_child_group(int pgid) {
  for (auto& g : g_groups) {
    int expected = 0;
    if (g.compare_exchange_strong(expected, pgid, std::memory_order_acq_rel)) return true;
  }
  return false;
}

void unregister_child_group(int pgid) {
  for (auto& g : g_groups) {
    int expected = pgid;
    if (g.compare_exchange_strong(expected, 0, std::memory_order_acq_rel)) return;
  }
}

TempFileGuard::TempFileGuard(const std::string& path) : path_(path) {
  if (path.size() >= PATH_MAX) return;
  for (std::size_t i = 0; i < kSlots; ++i) {
    int expected = kFree;
    if (g_temp[i].state.compare_exchange_strong(expected, kFilling, std::memory_order_acq_rel)) {
      std::memcpy(g_temp[i].path, path.c_str(), path.size() + 1);
      g_temp[i].state.store(kReady, std::memory_order_release);
      slot_ = static_cast<int>(i);
      return;
    }
  }
}

TempFileGuard::~TempFileGuard() {
  if (!committed_) ::unlink(path_.c_str());
  if (slot_ >= 0) g_temp[static_cast<std::size_t>(slot_)].state.store(kFree, std::memory_order_release);
}

}  // namespace oneshot::util
