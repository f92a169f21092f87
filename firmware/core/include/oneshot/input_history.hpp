/// @file input_history.hpp
/// @brief The inputs applied since an estimate's instant: a small ring of input changes.
///
/// Entry 0 is the input active at the estimate instant (offset 0); entry k > 0 is an input
/// change applied offset_us(k) µs after it, offsets non-decreasing (two changes at the same
/// instant make a segment of zero length). A prediction over Δt crosses every change with
/// offset ≤ Δt (kalman_estimator.hpp); rebase(Δt) then moves the origin to the new
/// estimate instant, keeping the input active there and the changes still ahead.
#pragma once

#include <cstddef>
#include <cstdint>

#include "oneshot/matrix.hpp"
#include "oneshot/status.hpp"
#include "oneshot/time_us.hpp"

namespace oneshot {

/// Up to Capacity input segments of an m-input plant in format S.
template <typename S, std::size_t M, std::size_t Capacity = 4>
class InputHistory {
  static_assert(Capacity >= 2, "a history holds the active input and at least one change");
  static_assert(Capacity <= 255, "the ring is indexed with 8 bits");

 public:
  using InputVec = Vector<S, M>;                       ///< One input.
  static constexpr std::size_t kCapacity = Capacity;   ///< Entries the ring holds.

  /// Only `u` active, from the estimate instant on.
  constexpr void reset(const InputVec& u) {
    head_ = 0;
    size_ = 1;
    at(0) = Entry{0, u};
  }

  /// Input `u` applied offset_us after the estimate instant. kOutOfRange (history
  /// unchanged) when the ring is full or offset_us precedes the last change.
  [[nodiscard]] constexpr Status push(DurationUs offset_us, const InputVec& u) {
    if (size_ >= Capacity || offset_us < at(size_ - 1).offset_us) return Status::kOutOfRange;
    at(size_) = Entry{offset_us, u};
    ++size_;
    return Status::kOk;
  }

  /// Moves the origin dt_us ≥ 0 later: the last input applied at or before it becomes
  /// entry 0 (offset 0), later changes keep their instants (offsets reduced by dt_us).
  constexpr void rebase(DurationUs dt_us) {
    while (size_ > 1 && at(1).offset_us <= dt_us) {
      head_ = static_cast<std::uint8_t>((head_ + 1U) % Capacity);
      --size_;
    }
    at(0).offset_us = 0;
    for (std::size_t k = 1; k < size_; ++k) at(k).offset_us -= dt_us;
  }

  /// Number of entries (≥ 1).
  constexpr std::size_t size() const { return size_; }
  /// Offset of entry k from the estimate instant (µs).
  constexpr DurationUs offset_us(std::size_t k) const { return at(k).offset_us; }
  /// Input of entry k.
  constexpr const InputVec& input(std::size_t k) const { return at(k).u; }
  /// The input applied last.
  constexpr const InputVec& latest() const { return at(size_ - 1).u; }
  /// Segments a prediction over dt_us crosses: entry 0 and every change at or before dt_us.
  constexpr std::size_t segments_within(DurationUs dt_us) const {
    std::size_t k = 1;
    while (k < size_ && at(k).offset_us <= dt_us) ++k;
    return k;
  }

 private:
  struct Entry {
    DurationUs offset_us;
    InputVec u;
  };
  constexpr Entry& at(std::size_t k) { return ring_[(head_ + k) % Capacity]; }
  constexpr const Entry& at(std::size_t k) const { return ring_[(head_ + k) % Capacity]; }

  Entry ring_[Capacity] = {};
  std::uint8_t head_ = 0;
  std::uint8_t size_ = 1;
};

}  // namespace oneshot
