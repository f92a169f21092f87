/// @file pil_experiments_test.cpp
/// @brief Closed loop through QEMU: the firmware's control job against the host's on the
///        same seeds (bit-identical inputs and estimates), under link faults, Table I
///        through the MCU, and the instruction counts of every variant.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <string>
#include <tuple>
#include <unistd.h>

#include "oneshot_experiments.hpp"
#include "oneshot/sim/pil_link.hpp"
#include "support/run_command.hpp"

namespace oneshot::sim {
namespace {

std::string out_dir(const std::string& name) {
  return (std::filesystem::temp_directory_path() / ("oneshot_pil_" + std::to_string(::getpid()) + "_" + name)).string();
}

Scenario scenario_named(const std::string& name, double duration_s) {
  Scenario s = find_scenario(default_scenarios(), name);
  s.duration_s = duration_s;
  return s;
}

CommonOptions common(NumberFormat format, DiscretizerKind disc, const std::string& name) {
  CommonOptions o;
  o.format = format;
  o.discretizer = disc;
  o.plots = false;
  o.out_dir = out_dir(name);
  return o;
}

using Combo = std::tuple<std::string, NumberFormat, DiscretizerKind>;

class ClosedLoop : public ::testing::TestWithParam<Combo> {};

TEST_P(ClosedLoop, McuAndHostAreBitIdentical) {
  // GIVEN the firmware image of this target, format and discretizer under QEMU
  const auto& [target, format, disc] = GetParam();
  const auto ctx = SimContext::reference();
  PilOptions p;
  p.target = target;
  const Scenario sc = scenario_named("j20-a0.5-p1", 2.0);
  for (Approach a : {Approach::kB, Approach::kC, Approach::kD}) {
    // WHEN the loop is closed through the MCU and, separately, on the host, same seed
    const auto j = run_pil_compare(*ctx, common(format, disc, "closed"), p, sc, a);
    // THEN every job's input and estimate agree bit for bit, hence the costs too
    SCOPED_TRACE(j.dump());
    EXPECT_EQ(j["target"], target);
    EXPECT_EQ(j["jobs"].get<int>(), 40);
    EXPECT_TRUE(j["bit_identical"].get<bool>());
    EXPECT_EQ(j["pil_cost"].get<double>(), j["host_cost"].get<double>());
    EXPECT_EQ(j["overruns"].get<int>(), 0);
    EXPECT_EQ(j["resends"].get<int>(), 0);
    EXPECT_LT(j["stack_peak_bytes"].get<int>(), 6144);  // STACK_SIZE of the linker script
  }
}

std::string combo_name(const ::testing::TestParamInfo<Combo>& param_info) {
  const std::string target = std::get<0>(param_info.param) == "cortex-m0" ? "M0" : "M4F";
  return target + "_" + to_string(std::get<1>(param_info.param)) + "_" + to_string(std::get<2>(param_info.param));
}

INSTANTIATE_TEST_SUITE_P(
    Images, ClosedLoop,
    ::testing::Combine(::testing::Values("cortex-m0", "cortex-m4f"),
                       ::testing::Values(NumberFormat::kFloat, NumberFormat::kFixed),
                       ::testing::Values(DiscretizerKind::kTable, DiscretizerKind::kNearest, DiscretizerKind::kGeneric)),
    combo_name);

TEST(ClosedLoopUnderLinkFaults, StaysBitIdentical) {
  // Every 4th request damaged in turn: corrupt byte, dropped byte, lost reply.
  const auto ctx = SimContext::reference();
  PilOptions p;
  p.target = "cortex-m0";
  p.fault_every = 4;
  p.timeout_ms = 100;
  const auto j = run_pil_compare(*ctx, common(NumberFormat::kFixed, DiscretizerKind::kTable, "faults"), p,
                                 scenario_named("j10-a0.2-p1", 1.0), Approach::kC);
  SCOPED_TRACE(j.dump());
  EXPECT_TRUE(j["bit_identical"].get<bool>());
  EXPECT_GE(j["resends"].get<int>(), 10);  // ≈ (1 config + 20 jobs + 20 ticks) / 4
}

TEST(PilTable1, SameCostsAsTheHostOnEveryApproach) {
  const auto ctx = SimContext::reference();
  PilOptions p;
  p.target = "cortex-m4f";
  std::vector<Scenario> scenarios = default_scenarios();
  for (Scenario& s : scenarios) s.duration_s = 1.0;
  const auto j = run_pil_table1(*ctx, common(NumberFormat::kFloat, DiscretizerKind::kTable, "table1"), p, scenarios, 2);
  EXPECT_EQ(j["scenarios"].get<int>(), 10);
  EXPECT_EQ(j["bit_identical_jobs"].get<int>(), j["jobs"].get<int>());
  for (const char* a : {"A", "B", "C", "D", "E"}) {
    const auto& r = j["approaches"][a];
    EXPECT_EQ(r["cost_mean"].get<double>(), r["host_cost_mean"].get<double>()) << a;
    EXPECT_GT(r["cost_ci95"].get<double>(), 0.0) << a;
  }
}

TEST(ExectimeTarget, CountsEveryVariantOnBothMcus) {
  const auto ctx = SimContext::reference();
  for (const std::string target : {"cortex-m0", "cortex-m4f"}) {
    PilOptions p;
    p.target = target;
    CommonOptions o = common(NumberFormat::kFloat, DiscretizerKind::kTable, "exectime");
    o.noise = NoiseModel::kConstant;
    const auto j = run_exectime_target(*ctx, o, p);
    SCOPED_TRACE(target);
    const auto per_job = [&](const std::string& v) { return j["variants"][v]["instructions_per_job"].get<double>(); };
    for (const char* fmt : {"float", "fixed"}) {
      for (const char* disc : {"table", "nearest", "generic"}) {
        for (const char* filter : {"half", "complete"}) {
          const std::string name = std::string(filter) + "_" + disc + "_" + fmt;
          ASSERT_TRUE(j["variants"].contains(name)) << name;
          const auto& v = j["variants"][name];
          EXPECT_GT(v["instructions_per_job"].get<double>(), 100) << name;
          EXPECT_LE(v["instructions_per_job_min"].get<double>(), v["instructions_per_job"].get<double>());
          EXPECT_NEAR(v["instructions_per_4s"].get<double>(),
                      v["instructions_per_job"].get<double>() * j["jobs_per_4s"].get<double>(), 1.0);
          EXPECT_GT(v["flash_bytes"].get<int>(), 1000) << name;
          EXPECT_GT(v["ram_bytes"].get<int>(), 100) << name;
        }
        // Instruction counts are deterministic: the orderings the design claims hold exactly.
        EXPECT_LT(per_job(std::string("half_") + disc + "_" + fmt), per_job(std::string("complete_") + disc + "_" + fmt));
      }
      EXPECT_LT(per_job(std::string("half_table_") + fmt), per_job(std::string("half_generic_") + fmt));
      EXPECT_LT(per_job(std::string("half_nearest_") + fmt), per_job(std::string("half_table_") + fmt));
    }
    if (target == "cortex-m0") {
      // No FPU: fixed point must beat the soft-float library clearly.
      EXPECT_LT(per_job("half_table_fixed") * 1.5, per_job("half_table_float"));
      EXPECT_LT(per_job("complete_table_fixed") * 1.5, per_job("complete_table_float"));
    } else {
      // Single-precision FPU: float is the cheaper format.
      EXPECT_LT(per_job("half_table_float"), per_job("half_table_fixed"));
    }
  }
}

TEST(PilCli, RefusesDoubleAndUnknownScenariosClearly) {
  const std::string sim = ONESHOT_SIM_PATH;
  auto r = test::run_command(sim + " pil --number-format double --no-plots --out " + out_dir("cli"));
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.output.find("float or fixed"), std::string::npos) << r.output;
  r = test::run_command(sim + " pil --scenario nope --no-plots --out " + out_dir("cli"));
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.output.find("nope"), std::string::npos) << r.output;
  r = test::run_command(sim + " pil --firmware-dir /nonexistent --no-plots --out " + out_dir("cli"));
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.output.find("firmware image not found"), std::string::npos) << r.output;
}

TEST(PilCli, JsonSummaryOfOneRun) {
  const std::string sim = ONESHOT_SIM_PATH;
  const auto r = test::run_command(sim + " pil --target cortex-m0 --number-format fixed --approach B --duration 1 "
                                         "--no-plots --json - --out " + out_dir("cli_json"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto j = nlohmann::json::parse(r.output);
  EXPECT_TRUE(j["bit_identical"].get<bool>());
  EXPECT_EQ(j["number_format"], "fixed");
  EXPECT_EQ(j["cost_relative_difference"].get<double>(), 0.0);
}

}  // namespace
}  // namespace oneshot::sim
