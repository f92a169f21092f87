/// @file table_view.hpp
/// @brief Layout of a Φ/Γ/Q_d look-up table (generated at build time or built on the host).
///
/// Grid: t_i = i·g for i = 0 … range/g. The index i is split in mixed radix
/// (i = d₀ + r₀·d₁ + r₀r₁·d₂ …, finest level first); level l stores the triples for
/// digits 1 … r_l − 1 at spacing r₀…r_{l−1}·g, and a grid point is the composition of
/// its non-zero digits (exact: Φ(a+b) = Φ(b)Φ(a), see discretization.hpp). One level is
/// the plain table; more levels trade look-up time for memory.
/// Only free values are stored: an entry's structural 0/1 entries and entries that
/// repeat another one (same function of t, e.g. Γ₂ ≡ Φ₁₂ for the double integrator)
/// map to a shared slot. Between grid points the residual δ = τ − t_i < g is covered
/// by a per-slot polynomial in r = δ/g (the Taylor series of each entry, truncated
/// below the format's precision by the generator).
#pragma once

#include <cstddef>
#include <cstdint>
#include <type_traits>

namespace oneshot {

/// Slot code of an entry that is structurally zero.
inline constexpr std::int8_t kSlotZero = -1;
/// Slot code of an entry that is structurally one.
inline constexpr std::int8_t kSlotOne = -2;

/// Most free values an n-state, m-input table can have: Φ, Γ and the upper triangle of Q_d.
constexpr std::size_t max_table_slots(std::size_t n, std::size_t m) { return n * n + n * m + n * (n + 1) / 2; }

/// Slot id type of an n-state, m-input table: 8 bits while every slot fits (n ≤ 8 for
/// m ≤ 2: the reference table keeps its bytes), 16 bits beyond (n = 16, m = 4: 456 slots).
/// Residual offsets use the unsigned type of the same width.
template <std::size_t N, std::size_t M>
using SlotIdFor = std::conditional_t<(max_table_slots(N, M) <= 127), std::int8_t, std::int16_t>;

/// Table storage in block floating point: 16-bit mantissas of entry values and 32-bit
/// mantissas of residual coefficients, each slot with its own scale 2^−frac.
struct BlockFixedStorage {};

/// A 16-bit table mantissa (its scale is the slot's value_frac).
struct Mantissa16 {
  std::int16_t raw;  ///< Mantissa.
};
/// A 32-bit residual-coefficient mantissa (its scale is the slot's residual_frac).
struct Mantissa32 {
  std::int32_t raw;  ///< Mantissa.
};

/// Element types of a table: floating tables store the scalar itself.
template <typename Storage>
struct TableElements {
  using Value = Storage;        ///< Entry values.
  using Coefficient = Storage;  ///< Residual coefficients.
};
/// Block floating point tables.
template <>
struct TableElements<BlockFixedStorage> {
  using Value = Mantissa16;        ///< Entry values.
  using Coefficient = Mantissa32;  ///< Residual coefficients.
};

/// Read-only description of a table whose values are stored as `Storage`, slot ids as
/// SlotId (int8_t or int16_t, see SlotIdFor).
template <typename Storage, typename SlotId = std::int8_t>
struct TableView {
  static_assert(std::is_same_v<SlotId, std::int8_t> || std::is_same_v<SlotId, std::int16_t>,
                "slot ids are 8 or 16 bits");
  using Value = typename TableElements<Storage>::Value;              ///< Entry value type.
  using Coefficient = typename TableElements<Storage>::Coefficient;  ///< Residual coefficient type.
  using Slot = SlotId;                                               ///< Slot id type.
  using Offset = std::make_unsigned_t<SlotId>;                       ///< Residual offset type.
  std::int32_t granularity_us;          ///< Grid step g (µs).
  std::int32_t range_us;                ///< Covered range [0, range] (µs), a multiple of g.
  std::uint8_t levels;                  ///< Number of radix levels (≥ 1).
  const std::uint16_t* radix;           ///< Radix of each level, finest first.
  const std::uint16_t* level_offset;    ///< Index of each level's first entry.
  std::uint16_t entries;                ///< Number of stored entries.
  std::uint16_t slots;                  ///< Free values per entry.
  std::uint16_t transition_slots;       ///< Slots [0, this) feed Φ or Γ; the rest only Q_d.
  const SlotId* phi_slot;               ///< n×n slot map of Φ (kSlotZero/kSlotOne/slot).
  const SlotId* gamma_slot;             ///< n×m slot map of Γ.
  const SlotId* qd_slot;                ///< n×n slot map of Q_d (symmetric).
  const Value* values;                  ///< entries × slots values, entry-major.
  const std::uint8_t* residual_low;     ///< Lowest degree of each slot polynomial.
  const std::uint8_t* residual_high;    ///< Highest degree of each slot polynomial.
  const Offset* residual_offset;        ///< First coefficient of each slot polynomial.
  std::uint16_t residual_count;         ///< Number of stored residual coefficients.
  const Coefficient* residual_coefficients;  ///< Per slot, degrees low … high, ascending.
  const std::int8_t* value_frac;        ///< Block fixed: scale 2^−frac of each slot's values.
  const std::int8_t* residual_frac;     ///< Block fixed: scale of each slot's coefficients.
};

/// Every byte of plant-specific data the look-up reads: values, residual coefficients,
/// slot maps, level arrays and residual indices.
template <typename Storage, typename SlotId>
constexpr std::size_t table_bytes(const TableView<Storage, SlotId>& v, std::size_t n, std::size_t m) {
  using V = typename TableView<Storage, SlotId>::Value;
  using C = typename TableView<Storage, SlotId>::Coefficient;
  const std::size_t values = sizeof(V) * static_cast<std::size_t>(v.entries) * v.slots + sizeof(C) * v.residual_count;
  const std::size_t maps = sizeof(SlotId) * (n * n + n * m + n * n);  // slot maps
  const std::size_t levels = 2 * sizeof(std::uint16_t) * v.levels;     // radix + offset
  const std::size_t residual_index = (2U + sizeof(SlotId)) * v.slots;  // low, high, offset
  const std::size_t scales = v.value_frac != nullptr ? 2U * v.slots : 0U;  // block fixed scales
  return values + maps + levels + residual_index + scales;
}

}  // namespace oneshot
