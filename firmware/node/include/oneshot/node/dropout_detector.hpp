/// @file dropout_detector.hpp
/// @brief The receiver's dropout detector for one modified send-on-delta node
///        (send-on-delta brief §4).
///
/// A modified-SOD node sends at least every n_t samples (rule 2b: k − k_last ≥ n_t), so
/// when nothing from it has arrived since step k_rx, at least
///
///     d = ⌊(k − k_rx) / n_t⌋
///
/// of its packets were lost (n_t = 0, plain SOD: silence proves nothing, d = 0). d is a
/// lower bound: several losses inside one window of n_t samples count as one.
#pragma once

#include <cstdint>

#include "oneshot/node/message.hpp"

namespace oneshot::node {

/// Detector of lost packets of one node from the silence since its last arrival.
class DropoutDetector {
 public:
  /// Detector for a node whose time rule fires after `n_t` samples (0: plain SOD, no detection).
  constexpr explicit DropoutDetector(std::uint32_t n_t) : n_t_(n_t) {}
  /// Plain SOD (no detection).
  constexpr DropoutDetector() = default;

  /// A packet of sample k arrived.
  constexpr void on_receive(SequenceNumber k) {
    k_rx_ = k;
    any_ = true;
  }
  /// True once a packet has arrived.
  constexpr bool any_received() const { return any_; }
  /// Sample index of the newest arrival (meaningful when any_received()).
  constexpr SequenceNumber last_received() const { return k_rx_; }
  /// Lost packets proven by the silence at step k (no arrival at k): ⌊(k − k_rx)/n_t⌋;
  /// 0 for plain SOD or before the first arrival. Wrap-safe (unsigned difference).
  constexpr std::uint32_t dropouts(SequenceNumber k) const {
    if (n_t_ == 0 || !any_) return 0;
    return (k - k_rx_) / n_t_;
  }
  /// The node's time rule in samples (0: none).
  constexpr std::uint32_t time_steps() const { return n_t_; }

 private:
  std::uint32_t n_t_ = 0;
  SequenceNumber k_rx_ = 0;
  bool any_ = false;
};

}  // namespace oneshot::node
