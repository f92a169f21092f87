/// @file parallel.hpp
/// @brief Runs independent tasks on every core; results land in task order.
#pragma once

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

#include "oneshot/util/progress_bar.hpp"

namespace oneshot::util {

/// Number of worker threads to use (`requested`, or every core when 0).
inline unsigned worker_count(unsigned requested) {
  if (requested > 0) return requested;
  const unsigned hw = std::thread::hardware_concurrency();
  return hw == 0 ? 1 : hw;
}

/// Calls f(i) for i in [0, n) on `threads` threads; rethrows the first exception.
template <typename F>
void parallel_for(std::size_t n, unsigned threads, ProgressBar* progress, F&& f) {
  std::atomic<std::size_t> next{0};
  std::exception_ptr error;
  std::mutex error_mutex;
  const auto worker = [&]() {
    for (;;) {
      const std::size_t i = next++;
      if (i >= n) return;
      try {
        f(i);
      } catch (...) {
        const std::lock_guard<std::mutex> lock(error_mutex);
        if (!error) error = std::current_exception();
        next = n;
        return;
      }
      if (progress != nullptr) progress->tick();
    }
  };
  const unsigned count = std::max(1U, std::min<unsigned>(threads, static_cast<unsigned>(n)));
  std::vector<std::thread> pool;
  for (unsigned t = 1; t < count; ++t) pool.emplace_back(worker);
  worker();
  for (std::thread& t : pool) t.join();
  if (error) std::rethrow_exception(error);
}

}  // namespace oneshot::util
