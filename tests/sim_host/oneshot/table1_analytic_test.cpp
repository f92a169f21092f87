/// @file table1_analytic_test.cpp
/// @brief `table1 --analytic`'s outputs on a made-up sweep: B/A over the scenarios both
///        cost-weighted and scenario-weighted with their 0.2 % decisions, and no ratio to A
///        published when A's analytic value is refused.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <unistd.h>
#include <vector>

#include "oneshot/engine/sweep.hpp"
#include "support/temp_files.hpp"
#include "table1_analytic.hpp"

namespace oneshot::sim {
namespace {

namespace fs = std::filesystem;

/// Cost of approach a (0: A, 1: B) in scenario s (0: small, 1: large) at seed index k: B is
/// 1 % above A in the small scenario and 0.1 % above in the large one (100× A's cost).
double made_up_cost(std::size_t a, std::size_t s, std::size_t k) {
  const double base = (s == 0 ? 1.0 : 100.0) * (1.0 + 0.01 * static_cast<double>(k));
  const double factor = a == 0 ? 1.0 : (s == 0 ? 1.01 : 1.001);
  return base * factor;
}

/// The sweep with A's first run refused when `refuse_a`.
engine::SweepResults made_up_sweep(bool refuse_a) {
  engine::SweepSpec spec;
  spec.study = "oneshot";
  spec.experiment = "table1_analytic";
  spec.approaches = {"A", "B"};
  spec.scenarios = {"small", "large"};
  spec.seeds = 4;
  spec.metrics = {"analytic", "analytic_refused", "analytic_mismatch", "cost", "out_of_range", "board_cost"};
  spec.config = {{"plant", "made up"}, {"linear_board", "made up"}, {"number_format", "double"}};
  return engine::run_sweep(
      spec, engine::Shard{}, 1,
      [&](std::size_t a, std::size_t s, std::uint64_t seed) {
        const std::size_t k = seed - spec.first_seed;
        const double c = made_up_cost(a, s, k);
        const double refused = refuse_a && a == 0 && s == 0 && k == 0 ? 1.0 : 0.0;
        return std::vector<double>{c, refused, 0.0, c, 0.0, c};
      },
      "test");
}

std::string out_dir(const char* name) {
  return test::made_dir(name, "out");
}

TEST(Table1Analytic, BOverAIsPublishedCostWeightedAndScenarioWeighted) {
  const std::string dir = out_dir("oneshot_t1an_weights");
  const nlohmann::json j = table1_analytic_outputs(made_up_sweep(false), dir);
  ASSERT_TRUE(j.contains("B_over_A"));
  const nlohmann::json& r = j["B_over_A"];
  // Oracles from the inputs: per seed, the ratio of the scenario-summed costs, and the mean of
  // the per-scenario ratios (the same for every seed here).
  const double cost_weighted = (made_up_cost(1, 0, 0) + made_up_cost(1, 1, 0)) / (made_up_cost(0, 0, 0) + made_up_cost(0, 1, 0));
  const double scenario_weighted = 0.5 * (1.01 + 1.001);
  EXPECT_NEAR(r["cost_weighted"]["analytic_mean"].get<double>(), cost_weighted, 1e-12);
  EXPECT_NEAR(r["scenario_weighted"]["analytic_mean"].get<double>(), scenario_weighted, 1e-12);
  EXPECT_EQ(r["cost_weighted"]["within_0_2_percent"], "yes");      // +0.109 %
  EXPECT_EQ(r["scenario_weighted"]["within_0_2_percent"], "no");   // +0.55 %
  EXPECT_EQ(r["scenarios_within"].get<std::size_t>(), 1U);         // large only
  EXPECT_EQ(r["scenarios"].get<std::size_t>(), 2U);
  const std::string md = j["markdown"].get<std::string>();
  EXPECT_NE(md.find("cost-weighted"), std::string::npos);
  EXPECT_NE(md.find("scenario-weighted"), std::string::npos);
  fs::remove_all(dir);
}

TEST(Table1Analytic, NoRatioToARefusedReference) {
  const std::string dir = out_dir("oneshot_t1an_refused");
  const nlohmann::json j = table1_analytic_outputs(made_up_sweep(true), dir);
  const nlohmann::json& b = j["approaches"]["B"];
  EXPECT_EQ(b["analytic_ratio_to_A"], "reference A refused");
  EXPECT_EQ(b["analytic_ratio_to_A_scenario_weighted"], "reference A refused");
  EXPECT_EQ(b["ratio_variance_reduction"], "reference A refused");
  EXPECT_TRUE(b.contains("analytic_mean"));  // B's own value holds
  EXPECT_FALSE(j.contains("B_over_A"));
  EXPECT_FALSE(j.contains("ratio_variance_reduction"));
  EXPECT_NE(j["markdown"].get<std::string>().find("reference A refused"), std::string::npos);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace oneshot::sim
