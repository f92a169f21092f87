/// @file cli_test.cpp
/// @brief `oneshot-sim dropping …` end to end: JSON of a run, and bad input refused by name.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <string>

#include "support/run_command.hpp"

namespace oneshot::dropping {
namespace {

const std::string kSim = ONESHOT_SIM_PATH;

TEST(DroppingCli, RunPrintsItsMetricsAsJson) {
  const auto r = test::run_command(kSim + " dropping run --t-hold 2 --delay 1 --steps 60 --no-plots --out " +
                                   ::testing::TempDir() + "dropping_cli --json - 2>/dev/null");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const nlohmann::json j = nlohmann::json::parse(r.output);
  EXPECT_EQ(j.at("experiment"), "run");
  EXPECT_GT(j.at("gamma").get<double>(), 0.0);
  EXPECT_GT(j.at("trace_p").get<double>(), 0.0);
}

TEST(DroppingCli, BadInputIsRefusedByName) {
  const auto hold = test::run_command(kSim + " dropping run --t-hold 9 2>&1");
  EXPECT_NE(hold.exit_code, 0);
  EXPECT_NE(hold.output.find("--t-hold"), std::string::npos) << hold.output;
  const auto plant = test::run_command(kSim + " dropping lambda-c --plant " + std::string(ONESHOT_PLANTS_DIR) +
                                       "/reference_board.json 2>&1");
  EXPECT_NE(plant.exit_code, 0);
  EXPECT_NE(plant.output.find("discrete plant"), std::string::npos) << plant.output;
}

}  // namespace
}  // namespace oneshot::dropping
