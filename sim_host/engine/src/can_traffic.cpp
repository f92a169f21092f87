/// @file can_traffic.cpp
/// @brief Periodic CAN streams (see can_traffic.hpp).
#include "oneshot/engine/can_traffic.hpp"

#include <algorithm>
#include <stdexcept>

namespace oneshot::engine {

CanTraffic::CanTraffic(Kernel& kernel, CanBus& bus, std::vector<CanStream> streams, std::vector<Duration> offsets,
                       SimTime end)
    : kernel_(kernel), bus_(bus), streams_(std::move(streams)), end_(end),
      jitter_rng_(kernel.stream(stream_name("can", bus.config().name, "jitter"))), releases_(streams_.size()),
      observed_(streams_.size()) {
  if (offsets.size() != streams_.size()) throw std::invalid_argument("CAN traffic: one offset per stream");
  release_id_ = kernel_.add_handler("CAN traffic release", [this](std::uint64_t i) { release(i); });
  queue_id_ = kernel_.add_handler("CAN traffic queue", [this](std::uint64_t i) { queued(i); });
  deliver_id_ = kernel_.add_handler("CAN traffic delivery", [this](std::uint64_t i) { delivered(i); });
  for (std::size_t i = 0; i < streams_.size(); ++i) {
    if (streams_[i].period.count() <= 0) throw std::invalid_argument("CAN traffic: stream '" + streams_[i].name + "' needs a period");
    if (offsets[i] <= end_) kernel_.schedule(kernel_.now() + offsets[i], EventClass::kCompute, release_id_, i);
  }
}

/// Argument of a frame's events: stream index in the top 16 bits, release number below.
constexpr std::uint64_t frame_arg(std::size_t stream, std::size_t n) { return (std::uint64_t{stream} << 48) | n; }

void CanTraffic::release(std::size_t i) {
  const CanStream& s = streams_[i];
  releases_[i].push_back(kernel_.now());
  const Duration j{jitter_rng_.uniform_int(0, s.jitter.count())};
  kernel_.schedule(kernel_.now() + j, EventClass::kCompute, queue_id_, frame_arg(i, releases_[i].size() - 1));
  if (kernel_.now() + s.period <= end_) kernel_.schedule(kernel_.now() + s.period, EventClass::kCompute, release_id_, i);
}

void CanTraffic::queued(std::uint64_t arg) {
  const std::size_t i = arg >> 48;
  bus_.queue(streams_[i].id, streams_[i].payload_bytes, deliver_id_, arg);
}

void CanTraffic::delivered(std::uint64_t arg) {
  const std::size_t i = arg >> 48;
  const Duration r = kernel_.now() - releases_[i][arg & ((std::uint64_t{1} << 48) - 1)];
  Observed& o = observed_[i];
  ++o.frames;
  o.worst = std::max(o.worst, r);
  if (r > streams_[i].deadline) ++o.misses;
}

}  // namespace oneshot::engine
