/// @file study_reference_test.cpp
/// @brief A study file's `reference` (square, steps, file; overridable per scenario): the
///        square wave written as steps costs what the params' square wave costs, bit for bit,
///        under every approach (examples/ncs.json: I, S, A, AK, AKx, AKl, SK, S+, IK;
///        sod_ge_oneshot.json: I, OSK, OS, OSp, IK; two_loops_can.json: each loop on its
///        own period); the same steps from a CSV file equal the
///        inline ones; a scenario's own reference wins over the file's; bad references (the
///        parser's and the loop's) are refused naming the field and, for a file, the line; the
///        same bytes on 1 and 2 threads.
#include <gtest/gtest.h>

#include <fstream>
#include <string>

#include "oneshot/engine/study_file.hpp"
#include "study_example.hpp"
#include "study_ncs_runner.hpp"
#include "study_ncs_sweep.hpp"
#include "support/temp_files.hpp"

namespace oneshot::study {
namespace {

const test_support::StudyExample kNcs("ncs.json");
const test_support::StudyExample kOs("sod_ge_oneshot.json");
const test_support::StudyExample kLoops("two_loops_can.json");

/// The square wave ±A of period T written as steps [t_s, ±A] up to `until_s`.
nlohmann::json square_steps(double amplitude, double period_s, double until_s) {
  nlohmann::json steps = nlohmann::json::array();
  for (int i = 0; i * period_s / 2 < until_s; ++i) steps.push_back({i * period_s / 2, i % 2 == 0 ? amplitude : -amplitude});
  return steps;
}

/// Every scenario of `j` with its params' square wave as a `reference` of steps (up to `until_s`).
void params_as_steps(nlohmann::json& j, double until_s) {
  for (auto& x : j["scenarios"]) {
    const double a = x["params"]["amplitude_volts"].get<double>();
    const double t = x["params"]["period_s"].get<double>();
    x["params"].erase("amplitude_volts");
    x["params"].erase("period_s");
    x["reference"] = {{"kind", "steps"}, {"steps", square_steps(a, t, until_s)}};
  }
}

/// Every metric of every run of `a` equals that of `b`, bit for bit.
void expect_same_runs(const engine::SweepResults& a, const engine::SweepResults& b) {
  ASSERT_EQ(a.spec.approaches, b.spec.approaches);
  ASSERT_EQ(a.spec.metrics, b.spec.metrics);
  for (std::size_t ap = 0; ap < a.spec.approaches.size(); ++ap)
    for (std::size_t x = 0; x < a.spec.scenarios.size(); ++x)
      for (std::size_t k = 0; k < a.spec.seeds; ++k)
        for (std::size_t m = 0; m < a.spec.metrics.size(); ++m)
          EXPECT_EQ(a.at(ap, x, k, m), b.at(ap, x, k, m)) << a.spec.metrics[m] << " " << a.spec.approaches[ap] << " " << x << " " << k;
}

TEST(StudyReference, TheSquareWaveAsStepsCostsWhatTheSquareWaveCostsUnderEveryApproach) {
  for (const test_support::StudyExample* ex : {&kNcs, &kOs, &kLoops}) {  // the loops: each on its own period
    const auto shorten = [](nlohmann::json& j) {  // two scenarios: T_r 2 s and 4 s
      if (j["scenarios"].size() > 2) j["scenarios"] = {j["scenarios"][0], j["scenarios"][2]};
    };
    const NcsStudy square = ex->study(shorten, 5);
    const NcsStudy steps = ex->study([&](nlohmann::json& j) { shorten(j); params_as_steps(j, 5); }, 5);
    ASSERT_TRUE(steps.scenarios[0].setpoint_changes);
    EXPECT_FALSE(square.scenarios[0].setpoint_changes);
    expect_same_runs(run_ncs_sweep(square, 2, 2, engine::Shard{}), run_ncs_sweep(steps, 2, 2, engine::Shard{}));
    // A `reference` of kind square is the params' square wave (the same scenario, the same spec).
    const NcsStudy given = ex->study(
        [&](nlohmann::json& j) {
          shorten(j);
          for (auto& x : j["scenarios"]) {
            x["reference"] = {{"kind", "square"}, {"amplitude_volts", x["params"]["amplitude_volts"]}, {"period_s", x["params"]["period_s"]}};
            x["params"].erase("amplitude_volts");
            x["params"].erase("period_s");
          }
        },
        5);
    EXPECT_EQ(run_outputs(run_ncs_sweep(square, 2, 1, engine::Shard{}), test::fresh_dir("oneshot_ref_test", "sq"), false).dump(),
              run_outputs(run_ncs_sweep(given, 2, 1, engine::Shard{}), test::fresh_dir("oneshot_ref_test", "given"), false).dump());
  }
}

TEST(StudyReference, AFileReferenceEqualsTheSameStepsInline) {
  const std::string dir = test::made_dir("oneshot_ref_test", "file");
  const nlohmann::json steps = square_steps(0.2, 2, 6);
  {
    std::ofstream f(dir + "/ref.csv");
    f << "t_s,value_volts\n# the square wave +-0.2 V, T_r 2 s\n";
    for (const auto& s : steps) f << s[0].get<double>() << "," << s[1].get<double>() << "\r\n";
  }
  const auto with = [&](const nlohmann::json& ref) {
    return [ref](nlohmann::json& j) {
      j["reference"] = ref;
      for (auto& x : j["scenarios"]) {
        x["params"].erase("amplitude_volts");
        x["params"].erase("period_s");
      }
    };
  };
  const NcsStudy inline_steps = kOs.study(with({{"kind", "steps"}, {"steps", steps}}), 5);
  const NcsStudy file_steps = kOs.study(with({{"kind", "file"}, {"path", dir + "/ref.csv"}}), 5);
  expect_same_runs(run_ncs_sweep(inline_steps, 2, 2, engine::Shard{}), run_ncs_sweep(file_steps, 2, 2, engine::Shard{}));
  // A scenario's own reference wins over the file's.
  const NcsStudy own = kOs.study(
      [&](nlohmann::json& j) {
        with({{"kind", "file"}, {"path", dir + "/ref.csv"}})(j);
        j["scenarios"][1]["reference"] = {{"kind", "steps"}, {"steps", {{0, 0}, {1.5, 0.3}}}};
      },
      5);
  EXPECT_EQ(own.scenarios[0].setpoint_changes->size(), file_steps.scenarios[0].setpoint_changes->size());
  ASSERT_EQ(own.scenarios[1].setpoint_changes->size(), 1U);
  EXPECT_EQ(own.scenarios[1].setpoint_changes->front().first, 30U);  // 1.5 s at h = 50 ms
  EXPECT_EQ(own.scenarios[1].setpoint_changes->front().second, 0.3);
  // The same bytes on 1 and 2 threads (the spec carries the steps' hash).
  const std::string one = run_outputs(run_ncs_sweep(own, 3, 1, engine::Shard{}), test::fresh_dir("oneshot_ref_test", "one"), false).dump();
  const std::string two = run_outputs(run_ncs_sweep(own, 3, 2, engine::Shard{}), test::fresh_dir("oneshot_ref_test", "two"), false).dump();
  EXPECT_EQ(one, two);
  EXPECT_NE(one.find("changes_fnv1a"), std::string::npos);
}

TEST(StudyReference, BadReferencesAreRefusedNamingTheFieldAndLine) {
  const auto top = [](const nlohmann::json& ref) {
    return [ref](nlohmann::json& j) {
      j["reference"] = ref;
      for (auto& x : j["scenarios"]) {
        x["params"].erase("amplitude_volts");
        x["params"].erase("period_s");
      }
    };
  };
  const auto steps = [&](const nlohmann::json& s) { return top({{"kind", "steps"}, {"steps", s}}); };
  kOs.expect_refused(steps({{0, 0.2}, {0, -0.2}}), "field 'reference.steps[1]'");      // not increasing
  kOs.expect_refused(steps({{0, 0.2}, {1, 1e300}}), "field 'reference.steps[1]'");     // out of range
  kOs.expect_refused(steps({{-1, 0.2}}), "field 'reference.steps[0]'");
  kOs.expect_refused(steps({{0, 0.2, 3}}), "field 'reference.steps[0]'");
  kOs.expect_refused(steps(nlohmann::json::array()), "field 'reference.steps'");
  kOs.expect_refused(steps({{0, 0.2}}), "field 'reference.steps': the set-point never changes");  // I would cost 0
  kOs.expect_refused(steps({{0, 0.2}, {30, -0.2}}), "field 'duration_s'");              // changes after the run (20 s)
  kOs.expect_refused(steps({{0, 0.2}, {1.01, -0.2}, {1.02, 0.2}}), "field 'reference.steps': steps 1 and 2");  // one period
  kOs.expect_refused(top({{"kind", "ramp"}}), "field 'reference.kind'");
  kOs.expect_refused(top({{"kind", "steps"}, {"steps", {{0, 1}}}, {"every", 2}}), "field 'reference.every'");
  kOs.expect_refused(top({{"kind", "square"}, {"amplitude_volts", 0}, {"period_s", 2}}), "field 'reference.amplitude_volts'");
  kOs.expect_refused(top({{"kind", "square"}, {"amplitude_volts", 0.2}, {"period_s", 0.13}}), "field 'reference.period_s'");
  // The params' square wave and a reference do not mix; without either the params are missing.
  kOs.expect_refused([&](nlohmann::json& j) { j["reference"] = {{"kind", "steps"}, {"steps", {{0, 1}, {1, 0}}}}; },
                     "field 'scenarios[0].params.amplitude_volts'");
  kOs.expect_refused([](nlohmann::json& j) { j["scenarios"][1]["params"].erase("period_s"); }, "field 'scenarios[1].params.period_s'");
  kOs.expect_refused(
      [](nlohmann::json& j) {
        j["scenarios"][1]["params"].erase("period_s");
        j["scenarios"][1]["params"].erase("amplitude_volts");
        j["scenarios"][1]["reference"] = {{"kind", "steps"}, {"steps", {{0, 1}}}};
      },
      "field 'scenarios[1].reference.steps'");
  // Files: missing, then per line.
  const std::string dir = test::made_dir("oneshot_ref_test", "bad");
  const auto file = [&](const char* name, const std::string& text) {
    std::ofstream(dir + "/" + name) << text;
    return top({{"kind", "file"}, {"path", dir + "/" + name}});
  };
  kOs.expect_refused(top({{"kind", "file"}, {"path", dir + "/none.csv"}}), "field 'reference.path'");
  kOs.expect_refused(file("h.csv", "t,v\n0,1\n"), "line 1: expected the header");
  kOs.expect_refused(file("n.csv", "t_s,value_volts\n0,1\n\n1,nan\n"), "line 4: expected two finite numbers");
  kOs.expect_refused(file("c.csv", "t_s,value_volts\n0,1,2\n"), "line 2: expected two finite numbers");
  kOs.expect_refused(file("o.csv", "t_s,value_volts\n0,1\n2,0\n1,0.5\n"), "line 4: times must increase strictly");
  kOs.expect_refused(file("r.csv", "t_s,value_volts\n0,1\n1,1e5\n"), "line 3: value_volts must be finite");
  kOs.expect_refused(file("e.csv", "t_s,value_volts\n# nothing\n"), "no steps after the header");
  kOs.expect_refused(file("x.csv", "t_s,value_volts\n0,0.5x\n"), "field 'reference.path'");
  // Two steps in one period (the loop's check): the file's lines, comments and blank lines counted.
  kOs.expect_refused(file("p.csv", "t_s,value_volts\n0,0.2\n# next\n\n1.01,-0.2\n1.02,0.2\n"),
                     "field 'reference.path': " + dir + "/p.csv lines 5 and 6 (t_s");
}

}  // namespace
}  // namespace oneshot::study
