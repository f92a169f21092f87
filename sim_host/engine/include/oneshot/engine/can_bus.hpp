/// @file can_bus.hpp
/// @brief A CAN bus whose delays come from the traffic: priority arbitration by
///        identifier, a bit rate, worst-case bit stuffing, non-preemptive transmission.
///
/// Frame length with worst-case stuffing (Davis, Burns, Bril & Lukkien, "Controller Area
/// Network (CAN) schedulability analysis: Refuted, revisited and revised", Real-Time
/// Systems 35(3), 2007, eq. 1):
///     C = (g + 8s + 13 + ⌊(g + 8s − 1)/4⌋) τ_bit,   g = 34 (11-bit identifiers) or 54 (29-bit),
/// s payload bytes (0 … 8), τ_bit = 1/bit rate; the 13 bits (CRC delimiter, acknowledge,
/// end of frame, inter-frame space) are not stuffed. An 8-byte standard frame is 135 bits.
///
/// Behaviour: frames queued by the nodes wait in one priority queue (ideal controllers:
/// the highest-priority pending frame of every node takes part). Whenever the bus is
/// idle, arbitration (EventClass::kBus, after every other event of the instant, so frames
/// queued at that very instant compete) starts the pending frame with the lowest
/// identifier (ties: the one queued first); it occupies the bus for C and cannot be
/// preempted; its receivers get it at the end of C (EventClass::kDelivery). Several loops
/// share one bus by giving their frames different identifiers.
#pragma once

#include <cstddef>
#include <cstdint>
#include <queue>
#include <string>
#include <vector>

#include "oneshot/engine/kernel.hpp"
#include "oneshot/engine/sim_time.hpp"

namespace oneshot::engine {

/// Bits of a CAN data frame with `payload_bytes` (0 … 8) under worst-case stuffing.
std::int64_t can_frame_bits(std::size_t payload_bytes, bool extended_ids);

/// A bus's definition.
struct CanBusConfig {
  std::string name = "can";      ///< Identifier.
  std::int64_t bit_rate = 500'000;  ///< Bits per second (must divide 10^9: τ_bit is whole ns).
  bool extended_ids = false;     ///< 29-bit identifiers (g = 54) instead of 11-bit (g = 34).
};

/// Counters of a bus.
struct CanBusStatistics {
  std::uint64_t frames = 0;       ///< Frames transmitted.
  Duration busy{0};               ///< Time the bus was transmitting.
  std::size_t max_pending = 0;    ///< Largest number of frames waiting at once.
};

/// One CAN bus on a kernel.
class CanBus {
 public:
  /// Bus `config` on `kernel` (std::invalid_argument when the bit rate does not divide 10^9).
  CanBus(Kernel& kernel, const CanBusConfig& config);
  CanBus(const CanBus&) = delete;
  CanBus& operator=(const CanBus&) = delete;

  /// τ_bit.
  Duration bit_time() const { return bit_time_; }
  /// Worst-case transmission time of a frame with `payload_bytes`.
  Duration frame_time(std::size_t payload_bytes) const {
    return bit_time_ * can_frame_bits(payload_bytes, config_.extended_ids);
  }
  /// Queues a frame at now; at the end of its transmission `on_delivered` runs with `arg`.
  void queue(std::uint32_t id, std::size_t payload_bytes, HandlerId on_delivered, std::uint64_t arg);
  /// Counters.
  const CanBusStatistics& statistics() const { return stats_; }
  /// The definition.
  const CanBusConfig& config() const { return config_; }

 private:
  struct Pending {
    std::uint32_t id;
    std::uint64_t order;
    Duration length;
    HandlerId handler;
    std::uint64_t arg;
  };
  struct Lower {
    bool operator()(const Pending& a, const Pending& b) const {
      return a.id != b.id ? a.id > b.id : a.order > b.order;  // min-heap on (id, order)
    }
  };
  void arbitrate();
  void end_of_frame();

  Kernel& kernel_;
  CanBusConfig config_;
  Duration bit_time_;
  std::priority_queue<Pending, std::vector<Pending>, Lower> pending_;
  std::uint64_t order_ = 0;
  bool busy_ = false;
  bool arbitration_scheduled_ = false;
  Pending current_{};
  HandlerId arbitrate_id_ = 0;
  HandlerId end_id_ = 0;
  CanBusStatistics stats_{};
};

}  // namespace oneshot::engine
