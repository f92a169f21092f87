/// @file study_ncs_scenario_map_test.cpp
/// @brief The reference approach's cost 0 (study_ncs_scenario_map.hpp): a set-point that never
///        changes is refused when I leads the ratios (it costs exactly 0, naming the field and
///        I), runs as a regulation study when IK leads (n > 6: IK holds 0 against the noise, its
///        cost positive, every ratio finite), and is refused naming IK when its noise is off.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "ncs_loop.hpp"
#include "study_example.hpp"
#include "study_ncs_runner.hpp"
#include "study_ncs_scenario_map.hpp"
#include "study_ncs_sweep.hpp"
#include "support/temp_files.hpp"

namespace oneshot::study {
namespace {

const test_support::StudyExample kBoard("ncs.json");
const test_support::StudyExample kFlexible("flexible_structure.json");

/// Every scenario of the file at amplitude 0 (its set-point 0 throughout).
void amplitude_zero(nlohmann::json& j) {
  for (nlohmann::json& x : j["scenarios"]) x["params"]["amplitude_volts"] = 0;
}

TEST(StudyNcsScenarioMap, AmplitudeZeroRunsWhenIKLeadsWithFiniteRatios) {
  const NcsStudy s = kFlexible.study(amplitude_zero, 1.0);
  ASSERT_EQ(s.approaches[0], ncs::Approach::kIK);  // n = 8: I cannot run, IK leads
  ASSERT_EQ(s.scenarios.size(), 2U);
  const nlohmann::json j = run_outputs(run_ncs_sweep(s, 3, 2, engine::Shard{}), test::made_dir("oneshot_scenario_map_test", "ik0"), false);
  const nlohmann::json& a = j.at("approaches");
  const double ik = a.at("IK").at("cost_mean").get<double>();
  const double sk = a.at("SK").at("cost_mean").get<double>();
  EXPECT_TRUE(std::isfinite(ik) && ik > 0) << ik;  // the plant's noise moves it off 0
  EXPECT_TRUE(std::isfinite(sk) && sk > 0) << sk;
  // The ratios: IK's 1, SK's the ratio of the cost means (the same doubles: measured 0 difference).
  EXPECT_EQ(a.at("IK").at("ratio_to_IK").get<double>(), 1.0);
  EXPECT_NEAR(a.at("SK").at("ratio_to_IK").get<double>(), sk / ik, 1e-12 * sk / ik);
  for (const char* k : {"ratio_mean", "ratio_ci95", "ratio_scenario_weighted"})
    EXPECT_TRUE(std::isfinite(a.at("SK").at(k).get<double>())) << k;
  // Direct: IK on the first scenario at amplitude 0 costs more than 0 on every seed.
  for (std::uint64_t seed = 1; seed <= 3; ++seed) EXPECT_GT(ncs::run(*s.ctx, ncs::Approach::kIK, s.scenarios[0], seed, {}).cost, 0);
  // Capped before where T_r/2 would be: still runs (IK's cost is the noise's).
  NcsStudy capped = kFlexible.study([](nlohmann::json&) {}, 8.0);
  cap_duration(capped, 1.0, "--max-duration");
  EXPECT_EQ(capped.scenarios[0].duration_s, 1.0);
}

TEST(StudyNcsScenarioMap, AmplitudeZeroIsRefusedNamingTheFieldAndTheLeadingApproach) {
  // I leads (the board's plant): it costs exactly 0 at amplitude 0, naming the field and I.
  kBoard.expect_refused(amplitude_zero, "field 'scenarios[0].params.amplitude_volts': amplitude 0 keeps the reference approach I "
                                        "at cost 0: no ratio to it");
  // IK leads without noise (noise_scale 0): it costs exactly 0 too, naming IK.
  const auto quiet = [](nlohmann::json& j) {
    amplitude_zero(j);
    j["scenarios"][1]["params"]["noise_scale"] = 0;
  };
  kFlexible.expect_refused(quiet, "field 'scenarios[1].params.amplitude_volts': amplitude 0 keeps the reference approach IK "
                                  "(noise_scale 0) at cost 0: no ratio to it");
  // A run ending before the first switch (T_r/2 = 2 s) without noise: the duration, naming IK.
  kFlexible.expect_refused(
      [](nlohmann::json& j) {
        j["scenarios"][0]["params"]["noise_scale"] = 0;
        j["scenarios"][0]["duration_s"] = 1;
      },
      "field 'scenarios[0].duration_s': the run ends (1.000000 s) before the first set-point switch at T_r/2 = 2.000000 s, so "
      "the reference approach IK (noise_scale 0) costs 0");
  // The same through cap_duration (study run --max-duration), `s` unchanged.
  NcsStudy s = kFlexible.study([](nlohmann::json& j) { j["scenarios"][0]["params"]["noise_scale"] = 0; }, 8.0);
  try {
    cap_duration(s, 1.0, "--max-duration");
    ADD_FAILURE() << "accepted";
  } catch (const engine::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("field '--max-duration': scenario a0.2-T4-d2-s1: the run ends"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("the reference approach IK (noise_scale 0) costs 0"), std::string::npos) << e.what();
  }
  EXPECT_EQ(s.scenarios[0].duration_s, 8.0);
  // zero_reference_cost directly: I at cost 0 whatever the noise, IK only without it.
  ncs::Scenario x = s.scenarios[1];  // noise_scale 4
  x.amplitude_volts = 0;
  EXPECT_EQ(zero_reference_cost(*s.ctx, x, ncs::Approach::kIK), "");
  EXPECT_NE(zero_reference_cost(*s.ctx, x, ncs::Approach::kI), "");
  x.noise_scale = 0;
  EXPECT_NE(zero_reference_cost(*s.ctx, x, ncs::Approach::kIK), "");
}

}  // namespace
}  // namespace oneshot::study
