/// @file structure_analysis_test.cpp
/// @brief Structural patterns from the plant graph.
#include <gtest/gtest.h>

#include "oneshot/design/structure_analysis.hpp"
#include "support/test_plants.hpp"

namespace oneshot::design {
namespace {

TEST(StructureAnalysis, DoubleIntegrator) {
  const auto p = reference_plant();
  const PlantPatterns s = analyse_structure(p, synthesize(p));
  // Φ = [[1, *], [0, 1]].
  EXPECT_TRUE(s.phi.is_one(0, 0));
  EXPECT_TRUE(s.phi.is_free(0, 1));
  EXPECT_TRUE(s.phi.is_zero(1, 0));
  EXPECT_TRUE(s.phi.is_one(1, 1));
  // Γ and Q_d dense; C = [1, 0]; the constant Q diagonal.
  EXPECT_TRUE(s.gamma.is_free(0, 0) && s.gamma.is_free(1, 0));
  EXPECT_TRUE(s.qd.is_free(0, 1));
  EXPECT_TRUE(s.output.is_one(0, 0) && s.output.is_zero(0, 1));
  EXPECT_TRUE(s.constant_q.is_zero(0, 1) && s.constant_q.is_free(0, 0));
}

TEST(StructureAnalysis, CycleMakesTheDiagonalFree) {
  const auto p = test::damped_oscillator();
  const PlantPatterns s = analyse_structure(p, synthesize(p));
  for (std::size_t i = 0; i < 2; ++i)
    for (std::size_t j = 0; j < 2; ++j) EXPECT_TRUE(s.phi.is_free(i, j)) << i << j;
}

TEST(StructureAnalysis, DecoupledStatesStayZero) {
  // ẋ₁ = −x₁ + u, ẋ₂ = −2x₂ (no path 1 → 2 or 2 → 1), noise on both.
  const auto p = parse_plant(test::plant_json("[[-1, 0], [0, -2]]", "[[1], [0]]", "[[1, 1]]"), "decoupled");
  const PlantPatterns s = analyse_structure(p, synthesize(p));
  EXPECT_TRUE(s.phi.is_zero(0, 1) && s.phi.is_zero(1, 0));
  EXPECT_TRUE(s.phi.is_free(0, 0));  // a self-loop is a cycle
  EXPECT_TRUE(s.gamma.is_zero(1, 0));
  EXPECT_TRUE(s.qd.is_zero(0, 1));
  EXPECT_EQ(s.phi.cpp_type(), "::oneshot::Pattern<2, 2, 0x6ULL, 0x0ULL>");
}

}  // namespace
}  // namespace oneshot::design
