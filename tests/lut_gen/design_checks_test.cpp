/// @file design_checks_test.cpp
/// @brief Configuration errors caught at design time with the cause named: undetectable
///        plants, missing deadbeat observers, missing feed-forward, estimation-only plants,
///        plant forms the fixed-size tools cannot take.
#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "oneshot/design/controller_synthesis.hpp"
#include "oneshot/design/fixed_size.hpp"
#include "support/test_plants.hpp"
#include "support/expect_error.hpp"

namespace oneshot::design {
namespace {

std::string plant_text(const std::string& file) {
  std::ifstream in(std::string(ONESHOT_PLANTS_DIR) + "/" + file, std::ios::binary);
  std::ostringstream o;
  o << in.rdbuf();
  return o.str();
}

std::string design_error(const PlantDescription& p) {
  try {
    synthesize(p);
  } catch (const DesignError& e) {
    return e.what();
  }
  return "";
}

TEST(DesignChecks, ReferenceReadOnV2IsRefusedAsUndetectable) {
  // Before: a prior covariance of 1.45e16 and exit 0. v1 (an integrator) is invisible in v2.
  const std::string e = design_error(parse_plant(test::reference_with("/C", "[[0, 1]]"), "v2-only"));
  EXPECT_NE(e.find("Kalman filter: (Phi, C) is not detectable"), std::string::npos) << e;
  EXPECT_NE(e.find("(|l| = 1)"), std::string::npos) << e;
}

TEST(DesignChecks, UnobservableStableStateLeavesNoDeadbeatObserver) {
  // x3 is stable and invisible in v1: detectable (the Kalman filter exists), not observable.
  const PlantDescription p = parse_plant(
      test::plant_json("[[0, -23.8, 0], [0, 0, 0], [0, 0, -5]]", "[[0], [-23.8], [1]]", "[[1, 0, 0]]"), "x3");
  const DesignResult d = synthesize(p);
  EXPECT_FALSE(d.deadbeat);
  EXPECT_NE(d.deadbeat_unavailable_reason.find("not observable"), std::string::npos) << d.deadbeat_unavailable_reason;
  for (double v : d.deadbeat_gain.values) EXPECT_EQ(v, 0.0);
  EXPECT_LT(d.estimator_radius, 1.0);
}

TEST(DesignChecks, MoreOutputsThanInputsNeedTrackedOutputs) {
  nlohmann::json j = nlohmann::json::parse(plant_text("networked_board.json"));
  j.erase("tracked_outputs");
  const DesignResult d = synthesize(parse_plant(j.dump(), "no-tracked"));
  EXPECT_FALSE(d.tracking);
  EXPECT_NE(d.tracking_unavailable_reason.find("declare tracked_outputs"), std::string::npos)
      << d.tracking_unavailable_reason;
}

TEST(DesignChecks, EstimationOnlyPlantHasNoLqrAndTheHarnessSaysSo) {
  const PlantDescription p = parse_plant(plant_text("send_on_delta_oscillator.json"), "sod");
  const DesignResult d = synthesize(p);
  EXPECT_FALSE(d.lqr_available);
  EXPECT_NE(d.lqr_unavailable_reason.find("no cost"), std::string::npos);
  test::expect_error_naming<DesignError>([&] { controller_design<double, 2, 1, 2>(p, d); }, {"no LQR gain"});
  EXPECT_THROW(require_continuous_board_and_table(p, "the harness"), PlantError);
}

TEST(DesignChecks, DiscretePlantHasNoContinuousModel) {
  const PlantDescription p = parse_plant(plant_text("sinopoli_dropping.json"), "sinopoli");
  const DesignResult d = synthesize(p);
  test::expect_error_naming<DesignError>([&] { continuous_model_per_us<double, 3, 1>(p, d); },
                                         {"needs a continuous plant"});
}

TEST(DesignChecks, LiteralHddDisturbanceHasNoSteadyStateKalmanFilter) {
  // Taken literally, x_d1 is never excited and sits on the unit circle: the steady-state
  // filter does not exist, and the design says so instead of returning a wrong gain.
  nlohmann::json j = nlohmann::json::parse(plant_text("hdd_numre.json"));
  j["sections"]["disturbance"] = {{"reading", "literal"},
                                  {"A_d", {{1.0, 0.0}, {-2.8419, 1.0}}},
                                  {"B_d", {{0.0}, {1.508e-4}}},
                                  {"C_d", {{0.0, 1e5}}}};
  const std::string e = design_error(parse_plant(j.dump(), "literal"));
  EXPECT_NE(e.find("Kalman"), std::string::npos) << e;
}

TEST(DesignChecks, CostOnExogenousDisturbanceStatesIsRefused) {
  nlohmann::json j = nlohmann::json::parse(plant_text("hdd_numre.json"));
  nlohmann::json q1 = nlohmann::json::array();
  for (int i = 0; i < 12; ++i) {
    nlohmann::json row = nlohmann::json::array();
    for (int k = 0; k < 12; ++k) row.push_back(i == k ? 1.0 : 0.0);
    q1.push_back(row);
  }
  j["cost"] = {{"Q1", q1}, {"Q2", {{1.0}}}};
  const std::string e = design_error(parse_plant(j.dump(), "weighted-disturbance"));
  EXPECT_NE(e.find("weights the exogenous disturbance states"), std::string::npos) << e;
}

TEST(DesignChecks, ToolsWithFixedSizesNameTheirLimit) {
  const PlantDescription p = parse_plant(plant_text("hdd_numre.json"), "hdd");
  test::expect_error_naming<PlantError>([&] { require_continuous_board_and_table(p, "lut_gen"); },
                                        {"lut_gen needs a continuous plant (this one is sections)"});
}

}  // namespace
}  // namespace oneshot::design
