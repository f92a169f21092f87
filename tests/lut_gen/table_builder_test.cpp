/// @file table_builder_test.cpp
/// @brief Table layout, slot sharing and the byte budget.
#include <gtest/gtest.h>

#include "oneshot/design/structure_analysis.hpp"
#include "oneshot/design/table_builder.hpp"
#include "support/test_plants.hpp"
#include "support/expect_error.hpp"

namespace oneshot::design {
namespace {

TableData<float> reference_table(std::int32_t max_bytes) {
  PlantDescription p = reference_plant();
  p.table_max_bytes = max_bytes;
  const DesignResult d = synthesize(p);
  return build_table<float>(p, d, analyse_structure(p, d));
}

TEST(TableBuilder, ReferenceStoresFiveFreeValuesPerEntry) {
  const TableData<float> t = reference_table(1023);
  // Φ₁₂, Γ₁, Q_d11, Q_d12, Q_d22; Γ₂ ≡ Φ₁₂ (both −23.8 t) shares a slot.
  EXPECT_EQ(t.slots, 5);
  EXPECT_EQ(t.transition_slots, 2);
  EXPECT_EQ(t.gamma_slot[1], t.phi_slot[1]);
  EXPECT_EQ(t.phi_slot[0], kSlotOne);
  EXPECT_EQ(t.phi_slot[2], kSlotZero);
  EXPECT_LT(t.bytes(), 1024U);
}

TEST(TableBuilder, FewestLevelsWithinTheBudget) {
  // One level needs 50 entries × 20 B = 1000 B of values plus residual and maps (> 1023).
  EXPECT_EQ(reference_table(1023).radix.size(), 2U);
  const TableData<float> small = reference_table(256);
  EXPECT_LE(small.bytes(), 256U);
  EXPECT_EQ(small.radix.size(), 3U);
  EXPECT_EQ(reference_table(1 << 20).radix.size(), 1U);
}

TEST(TableBuilder, EntriesCoverEveryGridPointByTheirDigits) {
  for (std::int32_t budget : {256, 1023, 1 << 20}) {
    const TableData<float> t = reference_table(budget);
    std::size_t spacing = 1;
    for (std::size_t l = 0; l < t.radix.size(); ++l) {
      const std::size_t first = t.level_offset[l];
      EXPECT_EQ(t.entry_time_us[first], static_cast<std::int32_t>(spacing) * t.granularity_us);
      spacing *= t.radix[l];
    }
    // The top level reaches the range.
    EXPECT_GE(static_cast<std::int32_t>(spacing) * t.granularity_us, t.range_us + t.granularity_us);
  }
}

TEST(TableBuilder, TooSmallBudgetIsRefusedWithTheNeededSize) {
  test::expect_error_naming<DesignError>([&] { reference_table(64); }, {"table.max_bytes", "needs"});
}

}  // namespace
}  // namespace oneshot::design
