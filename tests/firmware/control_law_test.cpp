/// @file control_law_test.cpp
/// @brief Control law, actuator quantisation and sensor conversion.
#include <gtest/gtest.h>

#include "oneshot/control_law.hpp"
#include "oneshot/design/controller_synthesis.hpp"
#include "oneshot/generated/plant_tables.hpp"

namespace oneshot {
namespace {

using generated::PlantConstants;
using generated::PlantStructure;
using generated::StateIndex;

TEST(ControlLaw, TracksTheSetPointEquilibrium) {
  using K = PlantConstants<double>;
  Vector<double, 2> x;
  x[StateIndex::kV1] = 0.2;
  x[StateIndex::kV2] = 0.0;
  Vector<double, 1> r;
  r[0] = 0.2;
  // At the equilibrium of the set-point the input is u_ref = N_u r = 0.
  EXPECT_DOUBLE_EQ((control_law<K::Format, PlantStructure>(K::kDesign, x, r)[0]), 0.0);
  // Away from it, u = −L (x − x_ref).
  x[StateIndex::kV1] = 0.3;
  x[StateIndex::kV2] = -0.05;
  const double expected = -(K::kDesign.l(0, 0) * 0.1 + K::kDesign.l(0, 1) * -0.05);
  EXPECT_NEAR((control_law<K::Format, PlantStructure>(K::kDesign, x, r)[0]), expected, 1e-15);
}

TEST(ControlLaw, QuantisesAndSaturatesTheActuator) {
  using K = PlantConstants<double>;
  const auto& act = K::kDesign.actuator;
  EXPECT_EQ(quantize_input(act, 0, -5.0), 0);
  EXPECT_EQ(quantize_input(act, 0, 5.0), act.steps);
  EXPECT_EQ(quantize_input(act, 0, 0.0), act.steps / 2);
  for (std::int32_t code : {0, 1, 999, 1000, 1999, 2000}) {
    EXPECT_EQ(quantize_input(act, 0, input_of_code(act, 0, code)), code);
  }
  // Rounds to the nearest step.
  const double step = input_of_code(act, 0, 1) - input_of_code(act, 0, 0);
  EXPECT_EQ(quantize_input(act, 0, input_of_code(act, 0, 700) + 0.49 * step), 700);
  EXPECT_EQ(quantize_input(act, 0, input_of_code(act, 0, 700) + 0.51 * step), 701);
}

TEST(ControlLaw, SensorCodesAreBinCentres) {
  using K = PlantConstants<double>;
  const auto& s = K::kDesign.sensor;
  const double lsb = 3.3 / 4096;
  EXPECT_NEAR(output_of_code(s, 0, 0), -1.65 + lsb / 2, 1e-15);
  EXPECT_NEAR(output_of_code(s, 0, 4095), 1.65 - lsb / 2, 1e-15);
}

}  // namespace
}  // namespace oneshot
