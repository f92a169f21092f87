/// @file study_plant_test.cpp
/// @brief A study file's inline plant (plant.continuous with the plant file's design keys):
///        examples/ncs.json with its plant file written inline gives the same output, bit for
///        bit (every cost and metric, plant_source aside), for a few seeds, and the same study
///        check; so does the board loop of two_loops_can.json written inline beside the servo's
///        plant file; what the loop cannot run (other shapes, C not the identity, missing design
///        keys, an unstabilizable or undetectable plant) and bad design keys (R not symmetric
///        or not positive definite, period 0, unknown keys and outputs, non-finite entries) are
///        refused naming the field; a first-order plant runs the sampling loops. The discrete
///        plant: study_discrete_plant_test.cpp.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <functional>
#include <string>

#include "ncs_loop.hpp"
#include "oneshot/engine/study_file.hpp"
#include "study_check.hpp"
#include "study_example.hpp"
#include "study_ncs_runner.hpp"
#include "study_ncs_sweep.hpp"
#include "study_plant_outputs.hpp"
#include "support/temp_files.hpp"

namespace oneshot::study {
namespace {

using test_support::inline_plant_of;
using test_support::outputs_of;

const test_support::StudyExample kInlineNcs("ncs.json");
const test_support::StudyExample kInlineLoops("two_loops_can.json");

TEST(StudyInlinePlant, NcsWithItsPlantFileWrittenInlineGivesTheSameBytes) {
  const auto inline_board = [](nlohmann::json& j) { j["plant"] = inline_plant_of("networked_board.json"); };
  const auto as_is = [](nlohmann::json&) {};
  NcsStudy file = kInlineNcs.study(as_is, 3);
  NcsStudy inl = kInlineNcs.study(inline_board, 3);
  file.scenarios.resize(3);
  inl.scenarios.resize(3);
  EXPECT_EQ(inl.plant_path, "");
  EXPECT_NE(inl.ctx->plant().source.find("plant.continuous"), std::string::npos);
  for (const std::uint64_t first : {1U, 17U}) {
    const std::string a = outputs_of(file, first, 3, "file");
    const std::string b = outputs_of(inl, first, 3, "inline");
    EXPECT_EQ(a, b) << "first seed " << first;
    EXPECT_NE(a.find("\"cost_mean\""), std::string::npos);
  }
  // study check: the same designs and approaches; the plant section says where it came from.
  nlohmann::json jf = kInlineNcs.json(), ji = kInlineNcs.json();
  inline_board(ji);
  nlohmann::json rf = resolve_study(kInlineNcs.parse(jf)), ri = resolve_study(kInlineNcs.parse(ji));
  EXPECT_EQ(ri.at("plant").at("kind"), "continuous");
  EXPECT_TRUE(ri.at("plant").at("designed").get<bool>());
  EXPECT_EQ(ri.at("plant").at("period_us"), rf.at("plant").at("period_us"));
  for (nlohmann::json* r : {&rf, &ri}) {
    r->erase("plant");
    r->erase("source");
  }
  EXPECT_EQ(rf.dump(), ri.dump());
}

TEST(StudyInlinePlant, OneLoopInlineBesideOneFromAFileGivesTheSameBytes) {
  const auto inline_board = [](nlohmann::json& j) { j["loops"][0]["plant"] = inline_plant_of("networked_board.json"); };
  const NcsStudy file = kInlineLoops.study([](nlohmann::json&) {}, 2);
  const NcsStudy inl = kInlineLoops.study(inline_board, 2);
  ASSERT_EQ(inl.loops.size(), 2U);
  EXPECT_EQ(outputs_of(file, 1, 2, "loops_file"), outputs_of(inl, 1, 2, "loops_inline"));
}

/// The inline board of ncs.json after `edit` of its plant.continuous object.
test_support::Edit edited_board(const test_support::Edit& edit) {
  return [edit](nlohmann::json& j) {
    j["plant"] = inline_plant_of("networked_board.json");
    edit(j["plant"]["continuous"]);
  };
}

TEST(StudyInlinePlant, WhatTheLoopCannotRunIsRefusedNamingTheKey) {
  const auto expect = [](const test_support::Edit& edit, const std::string& what) {
    kInlineNcs.expect_refused(edited_board(edit), what, true);
  };
  // Other shapes run (StudyPlantShapes.*); without the design keys the first missing key is named.
  const auto bare = [](nlohmann::json& c) {
    for (const char* k : {"name", "states", "inputs", "outputs", "period_us", "tracked_outputs", "board", "measurement_covariance"})
      c.erase(k);
  };
  // C not the identity runs I, SK, IK: S (y fed back as x) is refused naming the approach.
  expect([](nlohmann::json& c) { c["C"] = {{1, 0}, {0, 2}}; }, "field 'approaches[1].kind': S feeds y back as the state");
  expect(bare, "field 'plant.continuous.measurement_covariance': missing");
  expect([](nlohmann::json& c) { c.erase("Q1c"); c.erase("Q2c"); }, "field 'plant.continuous.Q1c'");
  expect([](nlohmann::json& c) { c.erase("board"); }, "field 'plant.continuous.board'");
  expect([](nlohmann::json& c) {
    c.erase("board");
    c["actuator"] = {{"u_min", {-1}}, {"u_max", {1}}};
  }, "field 'plant.continuous.board'");
  // Unstabilizable: the unstable first state is not reachable from u.
  expect([](nlohmann::json& c) { c["A"] = {{1, 0}, {0, 0}}; c["B"] = {{0}, {1}}; }, "field 'plant.continuous': design: LQR");
  // Undetectable (p = 1: the check designs it before the loop refuses the shape): the unstable
  // second state is invisible in the one output.
  expect([](nlohmann::json& c) {
    c["A"] = {{0, 0}, {0, 1}};
    c["B"] = {{1}, {1}};
    c["C"] = {{1, 0}};
    c["outputs"] = {"v1"};
    c["measurement_covariance"] = {{8e-5}};
    c["board"]["adc_min_volts"] = {-1.65};
    c["board"]["adc_max_volts"] = {1.65};
  }, "field 'plant.continuous': design: Kalman filter");
  // A discrete plant without the design keys.
  kInlineNcs.expect_refused([](nlohmann::json& j) {
    j["plant"] = {{"discrete", {{"Phi", {{1, 0.1}, {0, 1}}}, {"Gamma", {{0}, {0.1}}}, {"C", {{1, 0}, {0, 1}}},
                                {"Q", {{1e-6, 0}, {0, 1e-6}}}, {"period_us", 50000}}}};
  }, "field 'plant.discrete.measurement_covariance': missing", true);
  // In a loops[] file the loop's index.
  kInlineLoops.expect_refused([](nlohmann::json& j) {
    j["loops"][0]["plant"] = inline_plant_of("networked_board.json");
    j["loops"][0]["plant"]["continuous"]["C"] = {{1, 0}, {0, 2}};
  }, "field 'buses': the bus analysis takes the board's frames");
}

TEST(StudyInlinePlant, BadDesignKeysAreRefusedNamingTheKey) {
  const auto expect = [](const test_support::Edit& edit, const std::string& what) {
    kInlineNcs.expect_refused(edited_board(edit), what);
  };
  const std::string r = "field 'plant.continuous.measurement_covariance'";
  expect([](nlohmann::json& c) { c["measurement_covariance"] = {{8e-5, 1e-5}, {0, 8e-5}}; }, r + ": not symmetric");
  expect([](nlohmann::json& c) { c["measurement_covariance"] = {{8e-5, 0}, {0, 0}}; }, r + ": must be positive definite");
  expect([](nlohmann::json& c) { c["measurement_covariance"] = {{8e-5, 0}, {0, -1e-5}}; }, r + ": not positive semidefinite");
  expect([](nlohmann::json& c) { c["measurement_covariance"] = {{8e-5, 0}}; }, r + ": is 1x2, expected 2x2");
  expect([](nlohmann::json& c) { c.erase("measurement_covariance"); }, r + ": missing");
  expect([](nlohmann::json& c) { c["period_us"] = 0; }, "field 'plant.continuous.period_us'");
  expect([](nlohmann::json& c) { c.erase("period_us"); }, "field 'plant.continuous.period_us': missing");
  expect([](nlohmann::json& c) { c["Q2c"] = {{0}}; }, "field 'plant.continuous.Q2c'");  // R of the LQR: positive definite
  expect([](nlohmann::json& c) { c["Q_c"] = {{0, 0}, {0, 0}}; }, "field 'plant.continuous.Q_c'");
  expect([](nlohmann::json& c) { c["noise"] = nlohmann::json::object(); }, "field 'plant.continuous.noise': unknown field");
  expect([](nlohmann::json& c) { c["tracked_outputs"] = {"v3"}; }, "field 'plant.continuous.tracked_outputs[0]'");
  expect([](nlohmann::json& c) { c["board"]["adc_bits"] = 0; }, "field 'plant.continuous.board.adc_bits'");
  expect([](nlohmann::json& c) { c["B_w"] = {{1}, {0}}; }, "field 'plant.continuous.B_w'");
  // Non-finite and duplicate keys (the text itself).
  nlohmann::json j = kInlineNcs.json();
  j["plant"] = inline_plant_of("networked_board.json");
  j["plant"]["continuous"]["measurement_covariance"][0][0] = "INF";
  std::string text = j.dump();
  text.replace(text.find("\"INF\""), 5, "1e999");
  EXPECT_THROW(engine::parse_study(text, kInlineNcs.path(), &ncs_schema(), ONESHOT_STUDY_EXAMPLES_DIR), engine::InputError);
  j["plant"]["continuous"]["measurement_covariance"][0][0] = 8e-5;
  std::string twice = j.dump();
  twice.replace(twice.find("\"period_us\":50000", twice.find("\"continuous\"")), 17, "\"period_us\":50000,\"period_us\":40000");
  try {
    static_cast<void>(engine::parse_study(twice, kInlineNcs.path(), &ncs_schema(), ONESHOT_STUDY_EXAMPLES_DIR));
    ADD_FAILURE() << "a duplicate key accepted";
  } catch (const engine::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("duplicate key 'period_us'"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace oneshot::study
