/// @file packet_buffer.hpp
/// @brief The actuator's buffer of a packet of future inputs (numre-petc.md §5).
///
/// A packet [u_k … u_{k+H}] sent at k replaces the one in force; at period j the actuator
/// applies entry j − k (j ≥ k) and holds the last entry beyond H. Before any packet: u0.
#pragma once

#include <cstddef>
#include <cstdint>

#include "oneshot/node/frame_status.hpp"

namespace oneshot::node {

/// Packet of H + 1 future inputs and the actuator logic around it.
template <typename S, std::size_t H>
class PacketBuffer {
 public:
  static constexpr std::size_t kEntries = H + 1;  ///< Entries per packet.

  /// Empty buffer that applies u0.
  constexpr explicit PacketBuffer(S u0 = S(0)) : hold_(u0) {}

  /// Takes the packet `u` (kEntries values) sent at period k: kOk, or kStale (refused) for a
  /// packet older than the one in force.
  [[nodiscard]] constexpr FrameStatus accept(std::uint32_t k, const S* u) {
    if (valid_ && static_cast<std::int32_t>(k - start_) < 0) return FrameStatus::kStale;
    for (std::size_t i = 0; i < kEntries; ++i) entries_[i] = u[i];
    start_ = k;
    valid_ = true;
    ++accepted_;
    return FrameStatus::kOk;
  }
  /// Input to apply at period j (entry j − k, the last one beyond H, u0 before any packet).
  constexpr S value(std::uint32_t j) const {
    if (!valid_) return hold_;
    const std::uint32_t idx = j - start_;
    if (static_cast<std::int32_t>(idx) < 0) return entries_[0];
    return idx > H ? entries_[H] : entries_[idx];
  }
  /// True when period j lies beyond the packet's horizon (the last entry is being held).
  constexpr bool exhausted(std::uint32_t j) const { return valid_ && j - start_ > H; }
  /// Period the packet in force was sent at.
  constexpr std::uint32_t start() const { return start_; }
  /// Whether a packet has arrived.
  constexpr bool valid() const { return valid_; }
  /// Packets accepted.
  constexpr std::uint32_t accepted() const { return accepted_; }

 private:
  S entries_[kEntries]{};
  S hold_;
  std::uint32_t start_ = 0;
  bool valid_ = false;
  std::uint32_t accepted_ = 0;
};

}  // namespace oneshot::node
