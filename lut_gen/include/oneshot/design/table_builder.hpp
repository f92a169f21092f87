/// @file table_builder.hpp
/// @brief Builds the Φ/Γ/Q_d look-up table of a plant in a storage format (host).
///
/// Steps: evaluate the triple on the whole grid with the generic routine in double;
/// assign a slot to each free entry (structural 0/1 entries get none, entries that are
/// the same function of t share one); derive each slot's sub-grid Taylor polynomial,
/// truncated below the storage precision; choose the radix layout with the fewest
/// levels that fits table.max_bytes (then the fewest bytes); round into the storage
/// format. See oneshot/table_view.hpp for how the firmware reads it.
#pragma once

#include <cstdint>
#include <string>
#include <type_traits>
#include <vector>

#include "oneshot/design/controller_synthesis.hpp"
#include "oneshot/design/plant_description.hpp"
#include "oneshot/design/structure_analysis.hpp"
#include "oneshot/table_view.hpp"

namespace oneshot::design {

/// Owning table data; view() gives the firmware's TableView. S is float, double, or
/// BlockFixedStorage (16-bit mantissas with a scale per slot).
template <typename S>
struct TableData {
  using Value = typename TableElements<S>::Value;              ///< Stored entry value.
  using Coefficient = typename TableElements<S>::Coefficient;  ///< Stored residual coefficient.
  std::int32_t granularity_us = 0;          ///< Grid step g.
  std::int32_t range_us = 0;                ///< Covered range.
  std::vector<std::uint16_t> radix;         ///< Per level, finest first.
  std::vector<std::uint16_t> level_offset;  ///< First entry of each level.
  std::vector<std::int32_t> entry_time_us;  ///< Time of each stored entry.
  std::uint16_t slots = 0;                  ///< Free values per entry.
  std::uint16_t transition_slots = 0;       ///< Slots used by Φ or Γ (first).
  std::vector<std::int16_t> phi_slot;       ///< n×n map.
  std::vector<std::int16_t> gamma_slot;     ///< n×m map.
  std::vector<std::int16_t> qd_slot;        ///< n×n map.
  std::vector<Value> values;                ///< entries × slots.
  std::vector<std::uint8_t> residual_low;   ///< Per slot.
  std::vector<std::uint8_t> residual_high;  ///< Per slot.
  std::vector<std::uint16_t> residual_offset;  ///< Per slot.
  /// The maps and offsets in 8 bits, filled when the plant's tables use 8-bit slot ids
  /// (max_table_slots(n, m) ≤ 127, see SlotIdFor): what view<std::int8_t>() points at.
  std::vector<std::int8_t> phi_slot8, gamma_slot8, qd_slot8;
  std::vector<std::uint8_t> residual_offset8;  ///< See phi_slot8.
  std::vector<Coefficient> residual_coefficients;  ///< Packed.
  std::vector<std::int8_t> value_frac;      ///< Block fixed: scale of each slot's values.
  std::vector<std::int8_t> residual_frac;   ///< Block fixed: scale of each slot's coefficients.
  double quantization_abs = 0;              ///< Worst |stored − exact| over values and coefficients.
  double quantization_rel = 0;              ///< Same, relative to the slot's largest value.
  std::size_t n = 0;                        ///< States.
  std::size_t m = 0;                        ///< Inputs.

  /// True when the tables of this plant use 8-bit slot ids (SlotIdFor<n, m>).
  bool narrow_slots() const { return max_table_slots(n, m) <= 127; }

  /// The firmware's view with slot ids SlotId (valid while this object lives and is not
  /// modified); std::int8_t needs narrow_slots() (checked: DesignError otherwise).
  template <typename SlotId = std::int8_t>
  TableView<S, SlotId> view() const {
    constexpr bool kNarrow = std::is_same_v<SlotId, std::int8_t>;
    if (kNarrow != narrow_slots()) {
      throw DesignError("table: a view with " + std::to_string(8 * sizeof(SlotId)) + "-bit slot ids of a " +
                        std::to_string(n) + "-state, " + std::to_string(m) + "-input table (SlotIdFor)");
    }
    const auto pick = [](const auto& narrow, const auto& wide) {
      if constexpr (kNarrow) {
        (void)wide;
        return narrow.data();
      } else {
        (void)narrow;
        return wide.data();
      }
    };
    return TableView<S, SlotId>{granularity_us,
                                range_us,
                                static_cast<std::uint8_t>(radix.size()),
                                radix.data(),
                                level_offset.data(),
                                static_cast<std::uint16_t>(entry_time_us.size()),
                                slots,
                                transition_slots,
                                pick(phi_slot8, phi_slot),
                                pick(gamma_slot8, gamma_slot),
                                pick(qd_slot8, qd_slot),
                                values.data(),
                                residual_low.data(),
                                residual_high.data(),
                                pick(residual_offset8, residual_offset),
                                static_cast<std::uint16_t>(residual_coefficients.size()),
                                residual_coefficients.data(),
                                value_frac.empty() ? nullptr : value_frac.data(),
                                residual_frac.empty() ? nullptr : residual_frac.data()};
  }
  /// Every byte the look-up reads (see table_bytes()).
  std::size_t bytes() const {
    return narrow_slots() ? table_bytes(view<std::int8_t>(), n, m) : table_bytes(view<std::int16_t>(), n, m);
  }
};

/// Builds the table of `plant` in storage format S (float, double or BlockFixedStorage)
/// within plant.table_max_bytes; DesignError when no layout fits.
template <typename S>
TableData<S> build_table(const PlantDescription& plant, const DesignResult& design, const PlantPatterns& patterns);

/// Largest errors of a table against the double generic routine.
struct TableAccuracy {
  double max_abs_error = 0;   ///< Max over Φ, Γ, Q_d entries.
  double phi_abs = 0;         ///< Max |ΔΦ|.
  double gamma_abs = 0;       ///< Max |ΔΓ|.
  double qd_abs = 0;          ///< Max |ΔQ_d|.
  double phi_rel = 0;         ///< Max |ΔΦ| / max|Φ| at the same τ.
  double gamma_rel = 0;       ///< Max |ΔΓ| / max|Γ|.
  double qd_rel = 0;          ///< Max |ΔQ_d| / max|Q_d|.
  std::size_t points = 0;     ///< Number of τ compared.
};

/// Compares the table with the double generic routine at every grid point, every
/// midpoint and a sweep of off-grid points up to twice the range (extension).
template <typename S>
TableAccuracy measure_accuracy(const TableData<S>& table, const PlantDescription& plant, const DesignResult& design);

}  // namespace oneshot::design
