/// @file time_us.hpp
/// @brief Time as a type: instants on a wrapping microsecond counter, signed durations.
///
/// An MCU's free-running timer wraps (32 bits of µs: every 71.6 min); the host counts in
/// 64 bits. An instant is a tick count modulo 2^bits; the difference of two instants is
/// the signed duration b − a taken modulo 2^bits and read in two's complement, which is
/// right whenever the true |b − a| < 2^(bits−1) (35.8 min on the MCU). Ordering is only
/// defined through that difference (`earlier()`), never by comparing raw counts, so code
/// that orders instants keeps working across the wrap.
#pragma once

#include <cstdint>
#include <type_traits>

#include "oneshot/status.hpp"

namespace oneshot {

/// Signed duration in µs as the core uses it (±35.8 min).
using DurationUs = std::int32_t;

/// An instant on a wrapping µs counter with unsigned representation Rep.
template <typename Rep>
class InstantUs {
  static_assert(std::is_unsigned_v<Rep> && sizeof(Rep) >= 4, "Rep must be an unsigned type of 32 bits or more");

 public:
  using Representation = Rep;               ///< Raw counter type.
  using Signed = std::make_signed_t<Rep>;   ///< Signed difference type.

  /// The counter's zero.
  constexpr InstantUs() = default;
  /// The instant whose counter reads `ticks_us`.
  constexpr explicit InstantUs(Rep ticks_us) : ticks_(ticks_us) {}

  /// Raw counter value (µs modulo 2^bits).
  constexpr Rep ticks() const { return ticks_; }

  /// This instant moved by a signed number of µs (wraps like the counter).
  constexpr InstantUs plus(Signed delta_us) const {
    return InstantUs(static_cast<Rep>(ticks_ + static_cast<Rep>(delta_us)));
  }

  /// later − earlier modulo 2^bits, read as signed: exact while |true difference| < 2^(bits−1).
  friend constexpr Signed operator-(InstantUs later, InstantUs earlier) {
    const Rep diff = static_cast<Rep>(later.ticks_ - earlier.ticks_);
    // Two's complement reading without implementation-defined conversion.
    constexpr Rep kSignBit = static_cast<Rep>(Rep{1} << (sizeof(Rep) * 8U - 1U));
    if ((diff & kSignBit) == 0U) return static_cast<Signed>(diff);
    return -static_cast<Signed>(static_cast<Rep>(~diff)) - 1;
  }

  /// Same counter value.
  friend constexpr bool operator==(InstantUs a, InstantUs b) { return a.ticks_ == b.ticks_; }
  /// Different counter values.
  friend constexpr bool operator!=(InstantUs a, InstantUs b) { return a.ticks_ != b.ticks_; }

 private:
  Rep ticks_ = 0;
};

/// a strictly before b (wrap-safe: through the signed difference).
template <typename Rep>
constexpr bool earlier(InstantUs<Rep> a, InstantUs<Rep> b) {
  return (b - a) > 0;
}

/// Instant of the MCU's 32-bit µs timer.
using McuInstant = InstantUs<std::uint32_t>;
/// Instant of the host's 64-bit µs clock.
using HostInstant = InstantUs<std::uint64_t>;

/// `to − from` as a core duration, refused (kOutOfRange, out untouched) when it does not
/// fit DurationUs or lies outside [min_us, max_us]: the single point where a time span
/// from a clock or a message enters the maths, so garbage never reaches a signed overflow.
template <typename Rep>
[[nodiscard]] constexpr Status checked_duration(InstantUs<Rep> from, InstantUs<Rep> to, DurationUs min_us, DurationUs max_us,
                                  DurationUs& out) {
  const auto d = to - from;
  if (d < static_cast<decltype(d)>(min_us) || d > static_cast<decltype(d)>(max_us)) return Status::kOutOfRange;
  out = static_cast<DurationUs>(d);
  return Status::kOk;
}

/// Largest |τ| (µs) a filter takes: 2^29 µs ≈ 537 s, far beyond any table's composed range
/// and any interval a job can mean, small enough that h − τ, a + b and rounding to a grid
/// cannot overflow 32 bits.
inline constexpr DurationUs kMaxTauUs = DurationUs{1} << 29;

/// Bounds τ to ±kMaxTauUs where it enters the core: kClamped (τ moved) beyond, else kOk.
[[nodiscard]] constexpr Status bound_tau(DurationUs& tau_us) {
  if (tau_us > kMaxTauUs) {
    tau_us = kMaxTauUs;
    return Status::kClamped;
  }
  if (tau_us < -kMaxTauUs) {
    tau_us = -kMaxTauUs;
    return Status::kClamped;
  }
  return Status::kOk;
}

}  // namespace oneshot
