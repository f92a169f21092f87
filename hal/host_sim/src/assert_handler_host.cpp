/// @file assert_handler_host.cpp
/// @brief oneshot::assert_failed() for host builds.
#include <atomic>
#include <cstdio>
#include <cstdlib>

#include "oneshot/assert_handler.hpp"
#include "oneshot/host/assert_hook.hpp"

namespace oneshot {
namespace {
std::atomic<host::AssertHook> g_hook{nullptr};
}  // namespace

host::AssertHook host::set_assert_hook(AssertHook hook) { return g_hook.exchange(hook); }

void assert_failed(const char* file, int line, const char* expression) {
  if (const host::AssertHook hook = g_hook.load()) hook(file, line, expression);
  std::fprintf(stderr, "%s:%d: invariant failed: %s\n", file, line, expression);
  std::abort();
}

}  // namespace oneshot
