/// @file cli_design_test.cpp
/// @brief `oneshot-sim design`: JSON keys and values, and refusal of bad files.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "oneshot/design/controller_synthesis.hpp"
#include "oneshot/design/plant_description.hpp"
#include "support/run_command.hpp"
#include "support/shipped_plants.hpp"
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

class CliDesignPlantFile : public ::testing::TestWithParam<const char*> {};

TEST_P(CliDesignPlantFile, PrintsTheDesignOfEveryShippedPlant) {
  const std::string path = std::string(ONESHOT_PLANTS_DIR) + "/" + GetParam();
  const auto r = test::run_command(std::string(ONESHOT_SIM_PATH) + " design --plant " + path + " --json -");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto j = nlohmann::json::parse(r.output);
  const auto p = design::load_plant_file(path);
  EXPECT_EQ(j["Phi_h"].size(), p.n());
  EXPECT_EQ(j["Gamma_h"].size(), p.n() * p.m());
  EXPECT_EQ(j["kalman_gain"].size(), p.n() * p.p());
  EXPECT_LT(j["estimator_spectral_radius"].get<double>(), 1.0);
  EXPECT_TRUE(j.contains("deadbeat_available"));
  EXPECT_TRUE(j.contains("lqr_available"));
  EXPECT_EQ(j.contains("disturbance"), p.q() != 0);  // absent, never null
}

INSTANTIATE_TEST_SUITE_P(Shipped, CliDesignPlantFile,
                         ::testing::ValuesIn(test::kShippedPlantFiles),
                         [](const ::testing::TestParamInfo<const char*>& i) { return test::plant_file_stem(i.param); });

TEST(CliDesign, DeviceAndDirectoryAreClearErrors) {
  const auto dev = test::run_command(std::string(ONESHOT_SIM_PATH) + " design --plant /dev/zero");
  EXPECT_NE(dev.exit_code, 0);
  EXPECT_NE(dev.output.find("not a regular file"), std::string::npos) << dev.output;
  const auto dir = test::run_command(std::string(ONESHOT_SIM_PATH) + " design --plant " + ONESHOT_PLANTS_DIR);
  EXPECT_NE(dir.exit_code, 0);
  EXPECT_NE(dir.output.find("is a directory"), std::string::npos) << dir.output;
}

TEST(CliDesign, UndetectablePlantIsANonZeroExit) {
  const std::string path = test::write_temp_file("v2_only.json", test::reference_with("/C", "[[0, 1]]"));
  const auto r = test::run_command(std::string(ONESHOT_SIM_PATH) + " design --plant " + path + " --json -");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.output.find("not detectable"), std::string::npos) << r.output;
}

TEST(CliDesign, Table1MarksApproachEUnavailableWithoutADeadbeatObserver) {
  // x3 stable and unobservable: no deadbeat observer, so E is skipped with the reason
  // (before: E ran with a zero observer gain).
  const std::string path = test::write_temp_file(
      "no_deadbeat.json",
      test::plant_json("[[0, -23.8, 0], [0, 0, 0], [0, 0, -5]]", "[[0], [-23.8], [1]]", "[[1, 0, 0]]"));
  const std::string scenarios = test::write_temp_file(
      "short_scenarios.json",
      R"({"scenarios": [{"name": "s1", "duration_s": 2, "setpoint": {"amplitude_volts": 0.2, "change_period_s": 1},)"
      R"( "jitter": {"model": "uniform", "release_min_us": 0, "release_max_us": 10000, "exec_min_us": 200,)"
      R"( "exec_max_us": 600}}]})");
  const auto r = test::run_command(std::string(ONESHOT_SIM_PATH) + " table1 --plant " + path + " --scenarios " +
                                   scenarios + " --seeds 2 --no-plots --out " + path + ".out --json -");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto j = nlohmann::json::parse(r.output.substr(r.output.find('{')));
  EXPECT_FALSE(j["approaches"]["E"]["available"].get<bool>());
  EXPECT_NE(j["approaches"]["E"]["unavailable_reason"].get<std::string>().find("not observable"), std::string::npos);
  EXPECT_FALSE(j["approaches"]["E"].contains("cost_mean"));
  EXPECT_TRUE(j["approaches"]["B"]["available"].get<bool>());
  const auto run = test::run_command(std::string(ONESHOT_SIM_PATH) + " run --plant " + path +
                                     " --approach E --scenario j5-a0.2-p1 --duration 1 --no-plots --out " + path + ".run");
  EXPECT_NE(run.exit_code, 0);
  EXPECT_NE(run.output.find("approach E is unavailable"), std::string::npos) << run.output;
}

}  // namespace
}  // namespace oneshot
