/// @file fixed_formats_test.cpp
/// @brief The design step's Q formats, and refusal of plants that do not fit.
#include <gtest/gtest.h>

#include "oneshot/design/fixed_formats.hpp"
#include "oneshot/design/structure_analysis.hpp"
#include "oneshot/design/table_builder.hpp"
#include "support/test_plants.hpp"
#include "support/expect_error.hpp"

namespace oneshot::design {
namespace {

TEST(FixedFormats, ReferenceBoardFormats) {
  const PlantDescription p = reference_plant();
  const DesignResult d = synthesize(p);
  const FixedFormats f = choose_fixed_formats(p, d);
  EXPECT_EQ(f.state.bits, 32);
  EXPECT_EQ(f.state.frac, 29);       // ±4 V
  EXPECT_EQ(f.transition.bits, 16);
  EXPECT_EQ(f.transition.frac, 13);  // |Φ| ≤ 2.38 over the complete filter's 100 ms
  EXPECT_EQ(f.covariance.bits, 32);
  EXPECT_GE(f.covariance.frac, 34);  // resolves 1e-4 of the smallest steady-state variance
  EXPECT_EQ(f.fraction.frac, 15);
  for (const QuantityFormat& q : f.table) {
    EXPECT_GE(q.format.max_value(), q.range) << q.name;
    EXPECT_LT(q.format.max_value(), 2.01 * q.range + q.format.resolution()) << q.name << ": a bit wasted";
  }
}

TEST(FixedFormats, FastUnstablePlantIsRefusedNamingTheTransition) {
  // e^{30·0.1} ≈ 20 over the complete filter's 100 ms: no 16-bit format keeps 11 fractional bits.
  const PlantDescription p = parse_plant(test::plant_json("[[30, 0], [1, -5]]", "[[1], [0]]", "[[1, 0]]"), "fast");
  const DesignResult d = synthesize(p);
  test::expect_error_naming<DesignError>([&] { choose_fixed_formats(p, d); }, {"transition"});
}

TEST(FixedFormats, HugeCovarianceRangeIsRefused) {
  // P0 = 1 next to R = 1e-9: 32 bits cannot span it with 1e-4 relative resolution.
  const std::string text = test::reference_with("/noise/initial_covariance", "[[1, 0], [0, 1]]");
  PlantDescription p = parse_plant(text, "wide");
  p.measurement_covariance(0, 0) = 1e-9;
  const DesignResult d = synthesize(p);
  test::expect_error_naming<DesignError>([&] { choose_fixed_formats(p, d); }, {"covariance"});
}

TEST(FixedFormats, ConstantsThatDoNotFitAreNamed) {
  QFormat q{16, 13};
  EXPECT_EQ(q.raw_of(1.0, "x"), 8192);
  test::expect_error_naming<DesignError>([&] { q.raw_of(5.0, "L[0][1]"); }, {"L[0][1]"});
}

TEST(FixedTable, SixteenBitMantissasWithAScalePerSlot) {
  const PlantDescription p = reference_plant();
  const DesignResult d = synthesize(p);
  const auto t = build_table<BlockFixedStorage>(p, d, analyse_structure(p, d));
  EXPECT_EQ(t.slots, 5);
  EXPECT_EQ(t.value_frac.size(), 5U);
  EXPECT_LT(t.bytes(), 1024U);
  // Each slot uses its 16 bits: the largest mantissa is above half scale.
  for (std::size_t s = 0; s < t.slots; ++s) {
    int biggest = 0;
    for (std::size_t e = 0; e < t.entry_time_us.size(); ++e) biggest = std::max(biggest, std::abs(t.values[e * t.slots + s].raw));
    EXPECT_GE(biggest, 16384) << "slot " << s;
  }
  EXPECT_LT(t.quantization_rel, 1.0 / 32768);
}

}  // namespace
}  // namespace oneshot::design
