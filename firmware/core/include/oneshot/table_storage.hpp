/// @file table_storage.hpp
/// @brief How a table discretizer reads values: floating scalars, or block fixed point.
#pragma once

#include <cstddef>
#include <cstdint>
#include <type_traits>

#include "oneshot/fixed_point.hpp"
#include "oneshot/scalar_traits.hpp"
#include "oneshot/table_view.hpp"

namespace oneshot {

/// A slot value with its own scale (block fixed point): value = raw · 2^−frac.
/// Trivial (no member initialisers): the discretizer's scratch array of slots is written
/// before it is read, and a zero fill per job costs a memset call on small MCUs.
struct ScaledValue {
  std::int32_t raw;  ///< Mantissa.
  std::int8_t frac;  ///< Scale.
};

/// Reading of a table with storage `Storage` and slot ids SlotId (floating tables).
template <typename Storage, typename SlotId = std::int8_t>
struct TableStorage {
  using View = TableView<Storage, SlotId>;  ///< The table type read.
  using Slot = Storage;  ///< A decoded slot value.

  /// Value of slot s in stored entry `entry`.
  static constexpr Slot entry(const View& v, std::size_t entry, std::size_t s) {
    return v.values[entry * v.slots + s];
  }
  /// Slot polynomial at r: r^low · (c_low + r·(c_low+1 + … + r·c_high)), Horner.
  template <typename F>
  static constexpr Slot residual(const View& v, std::size_t s, F r) {
    const Storage* c = v.residual_coefficients + v.residual_offset[s];  // c[k] ↔ r^(low+k)
    const std::uint8_t low = v.residual_low[s];
    const std::uint8_t high = v.residual_high[s];
    Storage acc = c[high - low];
    for (std::uint8_t k = high; k > low; --k) acc = acc * r + c[k - 1 - low];
    for (std::uint8_t k = 0; k < low; ++k) acc = acc * r;
    return acc;
  }
  /// A slot value in format To.
  template <typename To>
  static constexpr To to(Slot x) {
    return convert<To>(x);
  }
};

/// Block fixed-point tables.
template <typename SlotId>
struct TableStorage<BlockFixedStorage, SlotId> {
  using View = TableView<BlockFixedStorage, SlotId>;  ///< The table type read.
  using Slot = ScaledValue;  ///< A decoded slot value.

  /// Value of slot s in stored entry `entry`.
  static constexpr Slot entry(const View& v, std::size_t entry, std::size_t s) {
    return Slot{v.values[entry * v.slots + s].raw, v.value_frac[s]};
  }
  /// Slot polynomial at r (Horner on 32-bit mantissas at the slot's residual scale).
  template <typename F>
  static constexpr Slot residual(const View& v, std::size_t s, F r) {
    static_assert(kIsFixed<F>, "block fixed tables need a fixed-point fraction r");
    const Mantissa32* c = v.residual_coefficients + v.residual_offset[s];
    const std::uint8_t low = v.residual_low[s];
    const std::uint8_t high = v.residual_high[s];
    std::int32_t acc = c[high - low].raw;
    for (std::uint8_t k = high; k > low; --k) {
      acc = detail::saturate<std::int32_t>(detail::round_shift(detail::wide_product(acc, r.raw()), F::kFrac) +
                                           c[k - 1 - low].raw);
    }
    for (std::uint8_t k = 0; k < low; ++k) {
      acc = detail::saturate<std::int32_t>(detail::round_shift(detail::wide_product(acc, r.raw()), F::kFrac));
    }
    return Slot{acc, v.residual_frac[s]};
  }
  /// A slot value in format To (32-bit arithmetic when narrowing, the usual case).
  template <typename To>
  static constexpr To to(Slot x) {
    const int shift = x.frac - To::kFrac;
    if (shift >= 0 && shift < 32) {
      return To::from_raw(detail::saturate<typename To::StorageType>(detail::round_shift32(x.raw, shift)));
    }
    return To::from_raw(detail::saturate<typename To::StorageType>(detail::round_shift(x.raw, shift)));
  }
};

}  // namespace oneshot
