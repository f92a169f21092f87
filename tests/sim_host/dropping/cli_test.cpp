/// @file cli_test.cpp
/// @brief `oneshot-sim dropping …` end to end: JSON of a run, and bad input refused by name.
#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "support/run_command.hpp"

namespace oneshot::dropping {
namespace {

const std::string kSim = ONESHOT_SIM_PATH;

TEST(DroppingCli, RunPrintsItsMetricsAsJson) {
  const std::string out = ::testing::TempDir() + "dropping_cli";
  const std::string json_path = ::testing::TempDir() + "dropping_cli_run.json";
  const auto r = test::run_command({kSim, "dropping", "run", "--t-hold", "2", "--delay", "1", "--steps", "60", "--no-plots",
                                    "--out", out, "--json", json_path});
  ASSERT_EQ(r.exit_code, 0) << r.output;
  std::ifstream in(json_path);
  std::stringstream text;
  text << in.rdbuf();
  const nlohmann::json j = nlohmann::json::parse(text.str());
  EXPECT_EQ(j.at("experiment"), "run");
  EXPECT_GT(j.at("gamma").get<double>(), 0.0);
  EXPECT_GT(j.at("trace_p").get<double>(), 0.0);
}

TEST(DroppingCli, BadInputIsRefusedByName) {
  const auto hold = test::run_command({kSim, "dropping", "run", "--t-hold", "9"});
  EXPECT_NE(hold.exit_code, 0);
  EXPECT_NE(hold.output.find("--t-hold"), std::string::npos) << hold.output;
  const auto plant = test::run_command(
      {kSim, "dropping", "lambda-c", "--plant", std::string(ONESHOT_PLANTS_DIR) + "/reference_board.json"});
  EXPECT_NE(plant.exit_code, 0);
  EXPECT_NE(plant.output.find("discrete plant"), std::string::npos) << plant.output;
}

}  // namespace
}  // namespace oneshot::dropping
