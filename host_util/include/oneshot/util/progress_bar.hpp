/// @file progress_bar.hpp
/// @brief Progress bar on standard error with the time elapsed and an ETA, shown only on
///        a terminal and only once a task has taken more than a second.
#pragma once

#include <atomic>
#include <chrono>
#include <cstddef>
#include <mutex>
#include <string>

namespace oneshot::util {

/// Thread-safe progress bar.
class ProgressBar {
 public:
  /// Bar for `total` steps labelled `label`.
  ProgressBar(std::string label, std::size_t total);
  ~ProgressBar();
  ProgressBar(const ProgressBar&) = delete;
  ProgressBar& operator=(const ProgressBar&) = delete;
  /// One step done.
  void tick();

 private:
  void draw(std::size_t done);
  std::string label_;
  std::size_t total_;
  std::atomic<std::size_t> done_{0};
  bool enabled_;
  bool shown_ = false;
  std::chrono::steady_clock::time_point start_;
  std::chrono::steady_clock::time_point last_draw_;
  std::mutex mutex_;
};

}  // namespace oneshot::util
