/// @file cli_design_test.cpp
/// @brief `oneshot-sim design`: JSON keys and values, and refusal of bad files.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "oneshot/design/controller_synthesis.hpp"
#include "support/run_command.hpp"
#include "support/test_plants.hpp"

namespace oneshot {
namespace {

TEST(CliDesign, JsonToStdoutHasTheDesign) {
  const auto r = test::run_command(std::string(ONESHOT_SIM_PATH) + " design --json -");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto j = nlohmann::json::parse(r.output);
  const auto d = design::synthesize(design::reference_plant());
  EXPECT_DOUBLE_EQ(j["h_s"].get<double>(), 0.05);
  ASSERT_EQ(j["Phi_h"].size(), 2U);
  EXPECT_DOUBLE_EQ(j["Phi_h"][0][1].get<double>(), d.phi_h(0, 1));
  EXPECT_DOUBLE_EQ(j["Gamma_h"][0].get<double>(), d.gamma_h(0, 0));
  EXPECT_DOUBLE_EQ(j["L"][0].get<double>(), d.l(0, 0));
  EXPECT_DOUBLE_EQ(j["L"][1].get<double>(), d.l(0, 1));
  EXPECT_DOUBLE_EQ(j["kalman_gain"][0].get<double>(), d.kalman_gain(0, 0));
}

TEST(CliDesign, PlantFileReplacesTheDefault) {
  const std::string path = test::write_temp_file("osc_design.json", test::plant_json("[[0, 1], [-900, -12]]", "[[0], [900]]", "[[1, 0]]"));
  const auto r = test::run_command(std::string(ONESHOT_SIM_PATH) + " design --plant " + path + " --json -");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(nlohmann::json::parse(r.output)["Phi_h"][1][0].get<double>(), 0.0);
}

TEST(CliDesign, BadPlantIsAClearErrorAndNonZeroExit) {
  const std::string path = test::write_temp_file("bad_design.json", test::reference_with("/period_us", "0"));
  const auto r = test::run_command(std::string(ONESHOT_SIM_PATH) + " design --plant " + path);
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.output.find("period_us"), std::string::npos) << r.output;
}

}  // namespace
}  // namespace oneshot
