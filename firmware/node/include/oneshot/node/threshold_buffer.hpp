/// @file threshold_buffer.hpp
/// @brief The threshold buffer of the over-delay dropping filter: a fixed ring of T_hold
///        slots keyed by the measurement's stamp (its sampling step j).
///
/// Before step k the buffer accepts the stamps of the window [k − T_hold, k − 1]: slot
/// j mod T_hold. A stamp older than the window is over-delayed (dropped, counted as a loss:
/// γ = 0), a stamp not yet sampled (j ≥ k) is refused, a second copy of a stamp already
/// held is a duplicate (the first copy stays). Packets may arrive in any order. Step k
/// takes stamp n = k − T_hold out of the ring (γ_n = whether it was there) and frees its
/// slot for stamp k. Stamps are 32-bit sequence numbers compared as serial numbers, so the
/// step counter may wrap. A value that is not finite is refused and counted (the buffer
/// never hands the filter NaN or ±∞); the stamp window itself is the sequence check (the
/// buffer's own step count is the reference, so no sender can move it). No heap, no
/// exceptions: it runs on an MCU.
#pragma once

#include <cstddef>
#include <cstdint>

#include "oneshot/finite.hpp"

namespace oneshot::node {

/// What happened to a received packet.
enum class ArrivalVerdict : std::uint8_t {
  kStored,       ///< In the window: kept for the filter.
  kDuplicate,    ///< Its stamp is already held: ignored.
  kOverDelayed,  ///< Older than the window (j < k − T_hold): dropped, γ_j = 0.
  kFuture,       ///< Stamp not yet sampled (j ≥ k): refused.
  kNonFinite,    ///< A value is NaN or ±∞: refused.
};

/// Counters of a ThresholdBuffer.
struct ThresholdBufferCounts {
  std::uint32_t stored = 0;        ///< Packets kept.
  std::uint32_t duplicates = 0;    ///< Second copies ignored.
  std::uint32_t over_delayed = 0;  ///< Packets older than the window.
  std::uint32_t future = 0;        ///< Packets stamped in the future.
  std::uint32_t refused_non_finite = 0;  ///< Packets with a NaN or ±∞ value.
  std::uint32_t taken = 0;         ///< Stamps the anchor consumed present (γ = 1).
  std::uint32_t missed = 0;        ///< Stamps the anchor consumed absent (γ = 0).
};

/// Ring of kHold slots holding measurements of type Y, keyed by stamp mod kHold.
template <typename Y, std::size_t kHold>
class ThresholdBuffer {
  static_assert(kHold >= 1, "T_hold must be at least one period");
  static_assert(kHold <= 255, "T_hold above 255 periods is refused (window offsets are 8-bit)");

 public:
  static constexpr std::size_t kSlots = kHold;  ///< T_hold.

  /// Empty buffer before step `next_step` (usually 0).
  constexpr explicit ThresholdBuffer(std::uint32_t next_step = 0) : next_(next_step) {}

  /// Offers the packet stamped `stamp` with value `y` (between steps).
  [[nodiscard]] constexpr ArrivalVerdict receive(std::uint32_t stamp, const Y& y) {
    if (!all_finite(y)) {
      ++counts_.refused_non_finite;
      return ArrivalVerdict::kNonFinite;
    }
    // age = k − j as a serial-number difference: 1 … T_hold is the window.
    const auto age = static_cast<std::int32_t>(next_ - stamp);
    if (age <= 0) {
      ++counts_.future;
      return ArrivalVerdict::kFuture;
    }
    if (age > static_cast<std::int32_t>(kHold)) {
      ++counts_.over_delayed;
      return ArrivalVerdict::kOverDelayed;
    }
    Slot& s = slots_[stamp % kHold];
    if (s.full && s.stamp == stamp) {
      ++counts_.duplicates;
      return ArrivalVerdict::kDuplicate;
    }
    s.full = true;
    s.stamp = stamp;
    s.value = y;
    ++counts_.stored;
    return ArrivalVerdict::kStored;
  }

  /// Whether stamp j (in the current window) is held; the value goes to `y` when it is.
  constexpr bool holds(std::uint32_t stamp, Y& y) const {
    const Slot& s = slots_[stamp % kHold];
    if (!s.full || s.stamp != stamp) return false;
    y = s.value;
    return true;
  }

  /// Step k: the oldest stamp of the window, n = k − T_hold (serial arithmetic).
  constexpr std::uint32_t oldest() const { return next_ - static_cast<std::uint32_t>(kHold); }

  /// Ends step k: takes stamp n = k − T_hold out (γ_n returned, its value in `y`) when
  /// `consume` (n ≥ 0 in the caller's count), frees its slot and moves to step k + 1.
  constexpr bool advance(bool consume, Y& y) {
    const std::uint32_t n = oldest();
    bool gamma = false;
    if (consume) {
      gamma = holds(n, y);
      if (gamma) ++counts_.taken; else ++counts_.missed;
    }
    Slot& s = slots_[n % kHold];
    if (s.stamp == n) s.full = false;
    ++next_;
    return gamma;
  }

  /// The step the buffer is waiting for (k).
  constexpr std::uint32_t next_step() const { return next_; }
  /// Counters.
  constexpr const ThresholdBufferCounts& counts() const { return counts_; }

 private:
  struct Slot {
    Y value{};
    std::uint32_t stamp = 0;
    bool full = false;
  };
  Slot slots_[kHold]{};
  std::uint32_t next_;
  ThresholdBufferCounts counts_{};
};

}  // namespace oneshot::node
