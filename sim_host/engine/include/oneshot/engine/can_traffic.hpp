/// @file can_traffic.hpp
/// @brief Periodic CAN message streams on a simulated bus (background load beside the
///        control loops, and the check of the response-time analysis), with the response
///        time of every frame observed.
///
/// Stream i releases frame n at o_i + n·T_i and queues it after a jitter drawn uniformly in
/// [0, J_i] (stream "can/<bus>/jitter"); its response time is the end of its transmission
/// minus its release, as in the analysis (can_analysis.hpp).
#pragma once

#include <cstdint>
#include <vector>

#include "oneshot/engine/can_analysis.hpp"
#include "oneshot/engine/can_bus.hpp"
#include "oneshot/engine/kernel.hpp"

namespace oneshot::engine {

/// Periodic streams on one bus.
class CanTraffic {
 public:
  /// What was observed of one stream.
  struct Observed {
    std::uint64_t frames = 0;   ///< Frames delivered.
    Duration worst{0};          ///< Largest response time.
    std::uint64_t misses = 0;   ///< Frames delivered after their deadline.
  };

  /// Streams `streams` with first releases `offsets` on `bus`, releasing while ≤ `end`.
  CanTraffic(Kernel& kernel, CanBus& bus, std::vector<CanStream> streams, std::vector<Duration> offsets, SimTime end);
  CanTraffic(const CanTraffic&) = delete;
  CanTraffic& operator=(const CanTraffic&) = delete;

  /// Per stream, in the order given.
  const std::vector<Observed>& observed() const { return observed_; }

 private:
  void release(std::size_t i);
  void queued(std::uint64_t arg);
  void delivered(std::uint64_t arg);

  Kernel& kernel_;
  CanBus& bus_;
  std::vector<CanStream> streams_;
  SimTime end_;
  RandomStream jitter_rng_;
  std::vector<std::vector<SimTime>> releases_;  // release instants, by stream and number
  std::vector<Observed> observed_;
  HandlerId release_id_ = 0;
  HandlerId queue_id_ = 0;
  HandlerId deliver_id_ = 0;
};

}  // namespace oneshot::engine
