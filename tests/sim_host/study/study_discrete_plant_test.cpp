/// @file study_discrete_plant_test.cpp
/// @brief A discrete plant (plant.discrete with the design keys, or a plant file of form
///        discrete) runs as its exact continuous equivalent: ncs.json with its plant written as
///        its ZOH sampling gives the costs of ncs.json to rounding; what has no such equivalent
///        (Φ with a negative real eigenvalue, a singular Φ, a Q no white noise gives) and a node
///        period other than the plant's are refused naming the field.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <functional>
#include <string>

#include "oneshot/design/plant_description.hpp"
#include "oneshot/design/sampled_model.hpp"
#include "oneshot/design/zoh_inverse.hpp"
#include "oneshot/engine/study_file.hpp"
#include "study_check.hpp"
#include "study_example.hpp"
#include "study_ncs_runner.hpp"
#include "study_plant_outputs.hpp"
#include "support/temp_files.hpp"

namespace oneshot::study {
namespace {

using test_support::outputs_of;

const test_support::StudyExample kDiscreteNcs("ncs.json");

nlohmann::json matrix_rows(const design::DenseMatrix& m) {
  nlohmann::json r = nlohmann::json::array();
  for (std::size_t i = 0; i < m.rows; ++i) {
    nlohmann::json row = nlohmann::json::array();
    for (std::size_t j = 0; j < m.cols; ++j) row.push_back(m(i, j));
    r.push_back(row);
  }
  return r;
}

/// The plant file at `path` as its ZOH sampling at its period (the design step's own sample_plant:
/// Φ, Γ, the per-step Q_d) inline as plant.discrete with the design keys.
nlohmann::json discrete_plant_at(const std::string& path) {
  const nlohmann::json p = nlohmann::json::parse(test::read_file(path));
  const design::SampledModel s = design::sample_plant(design::load_plant_file(path));
  nlohmann::json c;
  for (const char* k : {"name", "states", "inputs", "outputs", "C", "period_us", "tracked_outputs", "board"}) c[k] = p.at(k);
  c["Phi"] = matrix_rows(s.phi);
  c["Gamma"] = matrix_rows(s.gamma);
  c["Q"] = matrix_rows(s.qd);
  c["Q1c"] = p.at("cost").at("Q1c");
  c["Q2c"] = p.at("cost").at("Q2c");
  c["measurement_covariance"] = p.at("noise").at("measurement_covariance");
  return {{"discrete", c}};
}

/// The plant file `name` of lut_gen/plants as discrete_plant_at() gives it.
nlohmann::json discrete_plant_of(const char* name) {
  return discrete_plant_at(std::string(ONESHOT_STUDY_EXAMPLES_DIR) + "/../../../lut_gen/plants/" + name);
}

/// Largest relative difference of the numbers under a "cost_mean" key (per approach, per scenario
/// and approach) of two outputs of the same structure; `compared` counts them.
double cost_difference(const nlohmann::json& a, const nlohmann::json& b, std::size_t& compared, bool in_cost = false) {
  double worst = 0;
  if (a.is_object()) {
    for (const auto& [k, v] : a.items()) {
      if (!b.contains(k)) {
        ADD_FAILURE() << "missing key " << k;
        continue;
      }
      worst = std::fmax(worst, cost_difference(v, b.at(k), compared, in_cost || k == "cost_mean"));
    }
  } else if (a.is_array()) {
    EXPECT_EQ(a.size(), b.size());
    for (std::size_t i = 0; i < a.size() && i < b.size(); ++i) worst = std::fmax(worst, cost_difference(a[i], b[i], compared, in_cost));
  } else if (in_cost && a.is_number() && b.is_number()) {
    const double x = a.get<double>();
    const double y = b.get<double>();
    const double scale = std::fmax(std::fabs(x), std::fabs(y));
    worst = scale > 0 ? std::fabs(x - y) / scale : 0.0;
    ++compared;
  }
  return worst;
}

// (b) ncs.json with its plant written as its ZOH sampling (Φ, Γ, Q_d: the design step's own) runs
// as its exact continuous equivalent: mean costs (per approach, and per scenario and approach)
// within rounding of the plant file's, on two seed ranges. Measured ≤ 7.7e−16 relative over
// 2 × 36 means (3 scenarios × 9 approaches × 3 seeds each); asserted 5e−15.
TEST(StudyDiscretePlant, NcsWithItsPlantAsItsZohSamplingGivesTheSameCosts) {
  const auto discrete = [](nlohmann::json& j) { j["plant"] = discrete_plant_of("networked_board.json"); };
  NcsStudy file = kDiscreteNcs.study([](nlohmann::json&) {}, 3);
  NcsStudy disc = kDiscreteNcs.study(discrete, 3);
  file.scenarios.resize(3);
  disc.scenarios.resize(3);
  EXPECT_TRUE(disc.ctx->plant().from_discrete);
  EXPECT_LT(disc.ctx->plant().d2c_relative_error, 1e-14);
  double worst = 0;
  for (const std::uint64_t first : {1U, 17U}) {
    std::size_t compared = 0;
    const double d = cost_difference(nlohmann::json::parse(outputs_of(file, first, 3, "disc_file")),
                                     nlohmann::json::parse(outputs_of(disc, first, 3, "disc_inline")), compared);
    EXPECT_GE(compared, 36U);  // 9 approaches, and each in 3 scenarios
    EXPECT_LT(d, 5e-15) << "first seed " << first;
    worst = std::fmax(worst, d);
  }
  std::printf("discrete plant: worst relative cost difference %.3g\n", worst);
  // study check: the recovered A, B and the reconstruction error.
  nlohmann::json j = kDiscreteNcs.json();
  discrete(j);
  const nlohmann::json r = resolve_study(kDiscreteNcs.parse(j));
  const nlohmann::json& e = r.at("plant").at("continuous_equivalent");
  EXPECT_EQ(r.at("plant").at("kind"), "discrete");
  EXPECT_NEAR(e.at("A")[0][1].get<double>(), -23.8, 23.8 * 1e-13);
  EXPECT_NEAR(e.at("B")[1][0].get<double>(), -23.8, 23.8 * 1e-13);
  EXPECT_NEAR(e.at("Q_c")[1][1].get<double>(), 4e-6, 4e-6 * 1e-12);
  EXPECT_LT(e.at("reconstruction_relative_error").get<double>(), 1e-14);
  EXPECT_FALSE(e.contains("warning")) << e.dump();  // κ₁(Φ) ≈ 5: nothing to warn of
}

/// The board's plant with a velocity pole at A₂₂ (1/s), sampled and written as plant.discrete.
nlohmann::json fast_pole_board(double a22) {
  const std::string board = std::string(ONESHOT_STUDY_EXAMPLES_DIR) + "/../../../lut_gen/plants/networked_board.json";
  nlohmann::json f = nlohmann::json::parse(test::read_file(board));
  f["A"][1][1] = a22;
  const std::string path = test::made_dir("oneshot_study_plant", "near_singular") + "/fast_pole_board.json";
  std::ofstream(path) << f.dump(2);
  return discrete_plant_at(path);
}

// (d) Φ near-singular is warned of by study check, not refused: the board's plant with a fast
// velocity pole (A₂₂ = −300 /s: e^{−300h} = e^{−15} at h = 50 ms, κ₁(Φ) above
// kZohInverseWarnCondition) resolves and designs, its continuous equivalent carrying the
// condition estimate and the warning, in the JSON and the text. At A₂₂ = −400 (e^{−20}) the
// recovered B no longer gives Γ back to its own precision (measured 8.1e−10 relative): refused
// naming Gamma (the whole-matrix error, scaled by ‖Γ‖/‖[[Φ, Γ], [0, I]]‖, let it pass before).
TEST(StudyDiscretePlant, ANearSingularPhiIsWarnedOfNotRefused) {
  nlohmann::json j = kDiscreteNcs.json();
  j["plant"] = fast_pole_board(-300.0);
  const nlohmann::json r = resolve_study(kDiscreteNcs.parse(j));
  const nlohmann::json& e = r.at("plant").at("continuous_equivalent");
  ASSERT_TRUE(e.contains("warning")) << e.dump();
  EXPECT_GT(e.at("phi_condition").get<double>(), design::kZohInverseWarnCondition);
  EXPECT_NEAR(e.at("A")[1][1].get<double>(), -300.0, 300.0 * 1e-6);  // ill-conditioned, still close
  const std::string text = describe_resolution(r);
  EXPECT_NE(text.find("  warning: Phi is near-singular (condition estimate "), std::string::npos) << text;
  std::printf("near-singular Phi: %s\n", e.at("warning").get<std::string>().c_str());
  kDiscreteNcs.expect_refused([](nlohmann::json& k) { k["plant"] = fast_pole_board(-400.0); },
                              "field 'plant.discrete.Gamma': the continuous plant from the logarithm samples back to Gamma");
}

// The same plant as a plant file of form discrete (with Q1c, Q2c and a board) maps like the inline one.
TEST(StudyDiscretePlant, APlantFileOfFormDiscreteRunsAsItsContinuousEquivalent) {
  nlohmann::json c = discrete_plant_of("networked_board.json").at("discrete");
  nlohmann::json f = {{"form", "discrete"}};
  for (const char* k : {"name", "states", "inputs", "outputs", "Phi", "Gamma", "C", "period_us", "tracked_outputs", "board"}) f[k] = c.at(k);
  f["cost"] = {{"Q1c", c.at("Q1c")}, {"Q2c", c.at("Q2c")}};
  f["noise"] = {{"process_covariance_per_period", c.at("Q")}, {"measurement_covariance", c.at("measurement_covariance")}};
  const std::string path = test::made_dir("oneshot_study_plant", "discrete_file") + "/discrete_board.json";
  std::ofstream(path) << f.dump(2);
  const NcsStudy s = kDiscreteNcs.study([&](nlohmann::json& j) { j["plant"] = {{"file", path}}; }, 3);
  EXPECT_TRUE(s.ctx->plant().from_discrete);
  EXPECT_TRUE(s.ctx->plant().continuous());
  EXPECT_NEAR(s.ctx->plant().a(0, 1), -23.8, 23.8 * 1e-13);
  // Φ with a negative real eigenvalue in the plant file: named as the plant file's field.
  f["Phi"] = {{-0.5, 0.1}, {0, 0.9}};
  std::ofstream(path) << f.dump(2);
  kDiscreteNcs.expect_refused([&](nlohmann::json& j) { j["plant"] = {{"file", path}}; }, "field 'Phi': eigenvalue -0.5");
  // A discrete cost (Q1, Q2 per step) beside a board: the plant converts, the loop's continuous
  // cost has no weights: refused, never run on empty Q1c, Q2c.
  f["Phi"] = c.at("Phi");
  f["cost"] = {{"Q1", {{1, 0}, {0, 1}}}, {"Q2", {{1}}}};
  std::ofstream(path) << f.dump(2);
  kDiscreteNcs.expect_refused([&](nlohmann::json& j) { j["plant"] = {{"file", path}}; }, "needs cost.Q1c and cost.Q2c");
}

// (c) Refusals naming the field: no real logarithm, a singular Φ, a Q no white noise gives, a
// node period other than the plant's sampling period, a discrete cost or disturbance beside the
// design keys.
TEST(StudyDiscretePlant, WhatHasNoContinuousEquivalentIsRefusedNamingTheKey) {
  const auto expect = [](const std::function<void(nlohmann::json&)>& edit, const std::string& what) {
    kDiscreteNcs.expect_refused([&](nlohmann::json& j) {
      j["plant"] = discrete_plant_of("networked_board.json");
      edit(j["plant"]["discrete"]);
    }, what, true);
  };
  const std::string g = "field 'plant.discrete.";
  expect([](nlohmann::json& c) { c["Phi"] = {{-0.5, 0.1}, {0, 0.9}}; }, g + "Phi': eigenvalue -0.5 on the negative real axis");
  expect([](nlohmann::json& c) { c["Phi"] = {{1, 0.1}, {0, 0}}; }, g + "Phi': singular");
  expect([](nlohmann::json& c) { c["Q"] = {{0, 0}, {0, 1e-7}}; }, g + "Q': the continuous intensity Q_c");
  expect([](nlohmann::json& c) { c["Q1"] = {{1, 0}, {0, 1}}; }, g + "Q1': with the design keys the cost is the continuous");
  expect([](nlohmann::json& c) { c["Gamma_w"] = {{1}, {0}}; }, g + "Gamma_w'");
  expect([](nlohmann::json& c) { c.erase("Q1c"); c.erase("Q2c"); }, g + "Q1c': missing");
  kDiscreteNcs.expect_refused([](nlohmann::json& j) {
    j["plant"] = discrete_plant_of("networked_board.json");
    j["nodes"][0]["period_us"] = 40000;
  }, "field 'nodes[0].period_us': must be the plant's period h = 50000 us");
}

}  // namespace
}  // namespace oneshot::study
