/// @file progress_bar.cpp
/// @brief Progress bar.
#include "oneshot/util/progress_bar.hpp"

#include <cstdio>
#include <unistd.h>

namespace oneshot::util {

ProgressBar::ProgressBar(std::string label, std::size_t total)
    : label_(std::move(label)), total_(total), enabled_(::isatty(STDERR_FILENO) != 0),
      start_(std::chrono::steady_clock::now()), last_draw_(start_) {}

ProgressBar::~ProgressBar() {
  if (shown_) {
    draw(done_.load());
    std::fputc('\n', stderr);
  }
}

void ProgressBar::tick() {
  const std::size_t done = ++done_;
  if (!enabled_) return;
  const auto now = std::chrono::steady_clock::now();
  if (now - start_ < std::chrono::seconds(1)) return;
  const std::lock_guard<std::mutex> lock(mutex_);
  if (now - last_draw_ < std::chrono::milliseconds(100) && done != total_) return;
  last_draw_ = now;
  shown_ = true;
  draw(done);
}

void ProgressBar::draw(std::size_t done) {
  const int width = 40;
  const double f = total_ == 0 ? 1.0 : static_cast<double>(done) / static_cast<double>(total_);
  const int fill = static_cast<int>(f * width);
  const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  // ETA from the mean rate so far: elapsed · (total − done) / done.
  const double eta = done == 0 ? 0.0 : elapsed * static_cast<double>(total_ - done) / static_cast<double>(done);
  std::fprintf(stderr, "\r%-10s [%.*s%*s] %5.1f%% %zu/%zu %6.1fs ETA %6.1fs", label_.c_str(), fill,
               "########################################", width - fill, "", 100 * f, done, total_, elapsed, eta);
  std::fflush(stderr);
}

}  // namespace oneshot::util
