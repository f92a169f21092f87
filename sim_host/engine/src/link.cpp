/// @file link.cpp
/// @brief Links (see link.hpp).
#include "oneshot/engine/link.hpp"

#include <algorithm>

namespace oneshot::engine {

Link::Link(const LinkConfig& config, std::uint64_t seed)
    : config_(config), delay_rng_(seed, stream_name("link", config.name, "delay")),
      loss_(config.loss, RandomStream(seed, stream_name("link", config.name, "loss"))) {}

std::optional<SimTime> Link::transmit(SimTime sent) {
  ++stats_.sent;
  const bool lost = loss_.next_lost();
  bool clamped = false;
  const Duration d = config_.delay.draw(delay_rng_, index_++, clamped);
  if (clamped) ++stats_.clamped;
  if (lost) {
    ++stats_.lost;
    return std::nullopt;
  }
  SimTime arrival = sent + d;
  if (config_.fifo) {
    arrival = std::max(arrival, last_arrival_);
  } else if (arrival < last_arrival_) {
    ++stats_.reordered;
  }
  last_arrival_ = std::max(last_arrival_, arrival);
  stats_.max_delay = std::max(stats_.max_delay, arrival - sent);
  return arrival;
}

}  // namespace oneshot::engine
