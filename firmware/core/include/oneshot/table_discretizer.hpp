/// @file table_discretizer.hpp
/// @brief Φ(τ), Γ(τ), Q_d(τ) from a look-up table (see table_view.hpp for the layout).
///
/// Out-of-range policy (documented in the README and tested):
///  * τ < 0 (sample after the actuation instant: a scheduling fault): clamped to 0,
///    status kClamped.
///  * range < τ ≤ (kMaxExtensions+1)·range with OutOfRange::kExtend: exact, by composing
///    the triple of `range` with itself and the in-range remainder; status kExtended.
///    The complete filter's argument up to 2h needs no bigger table.
///  * beyond that, or any τ > range with OutOfRange::kClamp: clamped to the largest
///    supported τ, status kClamped.
/// No index is ever formed outside the stored entries.
#pragma once

#include <cstddef>
#include <cstdint>

#include "oneshot/assert_handler.hpp"
#include "oneshot/discretization.hpp"
#include "oneshot/status.hpp"
#include "oneshot/table_storage.hpp"
#include "oneshot/table_view.hpp"

namespace oneshot {

/// How τ between grid points is handled.
enum class SubGrid : std::uint8_t {
  kExact,    ///< Compose the grid entry with the residual's Taylor polynomial: exact.
  kNearest,  ///< Round τ to the nearest grid point (the original design): no residual
             ///< or composition, at the price of a timing error of up to g/2.
};

/// What to do with τ beyond the table range.
enum class OutOfRange : std::uint8_t {
  kExtend,  ///< Exact composition up to kMaxExtensions extra ranges, then clamp.
  kClamp,   ///< Clamp to the range.
};

/// Table-driven discretizer for a plant with structure `Structure`.
template <typename Fmt, typename Structure, typename Storage, OutOfRange kPolicy = OutOfRange::kExtend,
          SubGrid kSubGrid = SubGrid::kExact>
class TableDiscretizer {
 public:
  static constexpr std::size_t kN = Structure::kStates;
  static constexpr std::size_t kM = Structure::kInputs;
  /// Compositions of the full range allowed beyond the table (kExtend).
  static constexpr std::int32_t kMaxExtensions = 3;
  using Triple = Discretization<Fmt, kN, kM>;  ///< What discretize() produces.
  using SlotId = SlotIdFor<kN, kM>;            ///< Slot id width of this plant's tables.
  using View = TableView<Storage, SlotId>;     ///< The table type it reads.

  /// Uses `view` (its arrays must outlive the discretizer). Every structural entry the
  /// patterns claim must be one in the table's slot maps (checked).
  constexpr explicit TableDiscretizer(const View& view)
      : view_(view), fraction_scale_(ScalarTraits<typename Fmt::Fraction>::fraction_scale(view.granularity_us)) {
    ONESHOT_ASSERT(view.levels >= 1 && view.granularity_us > 0 && view.range_us > 0);
    ONESHOT_ASSERT(view.range_us % view.granularity_us == 0);
    ONESHOT_ASSERT(maps_match_structure(view));
  }

  /// True when the slot maps of `view` agree with Structure (usable in static_assert).
  static constexpr bool maps_match_structure(const View& view) {
    using PhiP = typename Structure::PhiPattern;
    using GammaP = typename Structure::GammaPattern;
    using QdP = typename Structure::QdPattern;
    for (std::size_t i = 0; i < kN; ++i) {
      for (std::size_t j = 0; j < kN; ++j) {
        if (!slot_matches<PhiP>(view.phi_slot[i * kN + j], i, j, view.slots)) return false;
        if (!slot_matches<QdP>(view.qd_slot[i * kN + j], i, j, view.slots)) return false;
      }
      for (std::size_t j = 0; j < kM; ++j)
        if (!slot_matches<GammaP>(view.gamma_slot[i * kM + j], i, j, view.slots)) return false;
    }
    return true;
  }

  /// The τ the filters use: unchanged (kExact), or rounded to the nearest grid point,
  /// ties away from zero, on both sides of 0 (kNearest; the filters round once, so that
  /// h − τ stays on the grid with τ, negative τ included; the generated C job rounds the
  /// same way). τ must lie within ±kMaxTauUs (the filters bound it first): no overflow.
  constexpr std::int32_t quantize(std::int32_t tau_us) const {
    if constexpr (kSubGrid == SubGrid::kNearest) {
      const std::int32_t g = view_.granularity_us;
      if (tau_us >= 0) return ((tau_us + g / 2) / g) * g;
      return -(((-tau_us) + g / 2) / g) * g;
    } else {
      return tau_us;
    }
  }

  /// Φ, Γ (and Q_d when asked) over τ_us, with the out-of-range policy above.
  [[nodiscard]] constexpr Status discretize(std::int32_t tau_us, Triple& out, WithQd with_qd) const {
    Status status = Status::kOk;
    if (tau_us < 0) {
      tau_us = 0;
      status = Status::kClamped;
    }
    const std::int32_t range = view_.range_us;
    if (tau_us <= range) {
      in_range(tau_us, with_qd, out);
      return status;
    }
    if constexpr (kPolicy == OutOfRange::kClamp) {
      in_range(range, with_qd, out);
      return Status::kClamped;
    } else {
      std::int32_t repeats = tau_us / range;
      std::int32_t remainder = tau_us - repeats * range;
      status = Status::kExtended;
      if (repeats > kMaxExtensions + 1 || (repeats == kMaxExtensions + 1 && remainder > 0)) {
        repeats = kMaxExtensions + 1;
        remainder = 0;
        status = Status::kClamped;
      }
      Triple full{NoInit{}};
      in_range(range, with_qd, full);
      if (remainder > 0) {
        in_range(remainder, with_qd, out);
      } else {
        out = full;
      }
      for (std::int32_t k = remainder > 0 ? 0 : 1; k < repeats; ++k) compose_into<Fmt, Structure>(out, full, with_qd);
      return status;
    }
  }

  /// The table in use.
  constexpr const View& view() const { return view_; }

 private:
  template <typename P>
  static constexpr bool slot_matches(SlotId slot, std::size_t i, std::size_t j, std::uint16_t slots) {
    if (P::is_zero(i, j)) return slot == kSlotZero;
    if (P::is_one(i, j)) return slot == kSlotOne;
    // A free pattern entry claims nothing: the table may still know it is 0 or 1.
    return slot == kSlotZero || slot == kSlotOne || (slot >= 0 && static_cast<int>(slot) < static_cast<int>(slots));
  }

  /// d = the triple for 0 ≤ τ ≤ range.
  constexpr void in_range(std::int32_t tau_us, WithQd with_qd, Triple& d) const {
    const std::int32_t g = view_.granularity_us;
    std::int32_t index = tau_us / g;
    const std::int32_t residual_us = tau_us - index * g;
    bool have = false;
    if (residual_us > 0) {
      ONESHOT_ASSERT(kSubGrid == SubGrid::kExact);  // kNearest: the filters quantize τ first
      residual(residual_us, with_qd, d);
      have = true;
    }
    Triple e{NoInit{}};
    for (std::uint8_t level = 0; level < view_.levels && index > 0; ++level) {
      const std::int32_t radix = view_.radix[level];
      const std::int32_t digit = index % radix;
      index /= radix;
      if (digit == 0) continue;
      const std::size_t entry = static_cast<std::size_t>(view_.level_offset[level]) +
                                static_cast<std::size_t>(digit - 1);
      ONESHOT_ASSERT(entry < view_.entries);
      if (have) {
        load_entry(entry, with_qd, e);
        compose_into<Fmt, Structure>(d, e, with_qd);
      } else {
        load_entry(entry, with_qd, d);
        have = true;
      }
    }
    ONESHOT_ASSERT(index == 0);  // range/g fits the radix levels (checked by the generator)
    if (!have) d = Triple::identity();
  }

  using Reader = TableStorage<Storage, SlotId>;
  using Slot = typename Reader::Slot;

  /// d = the triple over δ = residual_us < g from the slot polynomials in r = δ/g.
  constexpr void residual(std::int32_t residual_us, WithQd with_qd, Triple& d) const {
    using F = typename Fmt::Fraction;
    const F r = ScalarTraits<F>::fraction(residual_us, fraction_scale_);
    Slot slot_values[kMaxSlots];  // slots [0, used) written; expand() reads no other
    ONESHOT_ASSERT(view_.slots <= kMaxSlots);
    const std::uint16_t used = with_qd == WithQd::kYes ? view_.slots : view_.transition_slots;
    for (std::uint16_t s = 0; s < used; ++s) slot_values[s] = Reader::residual(view_, s, r);
    expand(slot_values, with_qd, d);
  }

  /// d = the triple of stored entry `entry`.
  constexpr void load_entry(std::size_t entry, WithQd with_qd, Triple& d) const {
    Slot slot_values[kMaxSlots];  // slots [0, used) written; expand() reads no other
    const std::uint16_t used = with_qd == WithQd::kYes ? view_.slots : view_.transition_slots;
    for (std::uint16_t s = 0; s < used; ++s) slot_values[s] = Reader::entry(view_, entry, s);
    expand(slot_values, with_qd, d);
  }

  /// d's matrices from one entry's free values (Q_d only when asked).
  constexpr void expand(const Slot* slot_values, WithQd with_qd, Triple& d) const {
    for (std::size_t i = 0; i < kN; ++i) {
      for (std::size_t j = 0; j < kN; ++j)
        d.phi(i, j) = pick<typename Fmt::Transition>(view_.phi_slot[i * kN + j], slot_values);
      for (std::size_t j = 0; j < kM; ++j)
        d.gamma(i, j) = pick<typename Fmt::InputGain>(view_.gamma_slot[i * kM + j], slot_values);
    }
    if (with_qd == WithQd::kYes) {
      for (std::size_t i = 0; i < kN; ++i)
        for (std::size_t j = 0; j < kN; ++j)
          d.qd(i, j) = pick<typename Fmt::Covariance>(view_.qd_slot[i * kN + j], slot_values);
    }
  }

  template <typename To>
  static constexpr To pick(SlotId slot, const Slot* slot_values) {
    if (slot == kSlotZero) return ScalarTraits<To>::zero();
    if (slot == kSlotOne) return ScalarTraits<To>::one();
    return Reader::template to<To>(slot_values[slot]);
  }

  /// Free values per entry supported (n² + nm + n(n+1)/2: 9 for the reference board, 456
  /// for n = 16, m = 4).
  static constexpr std::size_t kMaxSlots = max_table_slots(kN, kM);

  View view_;
  typename ScalarTraits<typename Fmt::Fraction>::FractionScale fraction_scale_;
};

}  // namespace oneshot
