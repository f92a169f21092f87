/// @file rx_ring.hpp
/// @brief Single-producer (interrupt) / single-consumer (main loop) byte ring.
#pragma once

#include <cstddef>
#include <cstdint>

namespace oneshot::mcu {

/// Bytes received by the UART interrupt, read by the main loop.
class RxRing {
 public:
  /// From the interrupt: stores b (drops it when full; the link protocol resends).
  void push(std::uint8_t b) {
    const std::size_t next = (head_ + 1) % kSize;
    if (next == tail_) return;
    data_[head_] = b;
    head_ = next;
  }
  /// From the main loop: takes one byte if there is one.
  [[nodiscard]] bool pop(std::uint8_t& b) {
    if (tail_ == head_) return false;
    b = data_[tail_];
    tail_ = (tail_ + 1) % kSize;
    return true;
  }
  /// Nothing to read.
  bool empty() const { return tail_ == head_; }

 private:
  static constexpr std::size_t kSize = 256;
  volatile std::uint8_t data_[kSize] = {};
  volatile std::size_t head_ = 0;
  volatile std::size_t tail_ = 0;
};

}  // namespace oneshot::mcu
