/// @file study_dropping_test.cpp
/// @brief "study": "dropping" files (sim_host/study/study_dropping_runner.cpp): the shipped
///        example against `oneshot-sim dropping closed-loop` on the same seeds, the delay models
///        mapped onto the arrival step, the same bytes on 1 and 2 threads and from merged shards,
///        and the refusals naming the field.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "oneshot/engine/study_file.hpp"
#include "oneshot/engine/sweep.hpp"
#include "oneshot/util/output_files.hpp"
#include "study_dropping_runner.hpp"
#include "support/run_command.hpp"
#include "support/temp_files.hpp"

namespace oneshot::study {
namespace {

const std::string kDroppingExample = std::string(ONESHOT_STUDY_EXAMPLES_DIR) + "/dropping.json";

nlohmann::json drop_example_json() { return nlohmann::json::parse(test::read_file(kDroppingExample)); }

std::shared_ptr<const DroppingStudy> drop_map_text(const nlohmann::json& j) {
  return map_dropping_study(engine::parse_study(j.dump(), kDroppingExample, &dropping_schema(), ONESHOT_STUDY_EXAMPLES_DIR));
}

/// Both null (a diverged mean) or within `rel` of each other.
void drop_expect_close(const nlohmann::json& a, const nlohmann::json& b, double rel, const std::string& what) {
  ASSERT_EQ(a.is_null(), b.is_null()) << what;
  if (a.is_null()) return;
  const double x = a.get<double>(), y = b.get<double>();
  EXPECT_LE(std::fabs(x - y), rel * std::fabs(y)) << what << ": " << x << " vs " << y;
}

TEST(StudyDropping, ExampleGivesTheCostsOfDroppingClosedLoop) {
  const std::string dir = test::made_dir("oneshot_study_dropping", "oracle");
  test::CommandOptions o;
  const test::CommandResult a = test::run_command({ONESHOT_SIM_PATH, "study", "run", kDroppingExample, "--seeds", "8", "--threads",
                                                   "2", "--out", dir + "/study", "--json", dir + "/study.json"}, o);
  ASSERT_EQ(a.exit_code, 0) << a.output;
  const test::CommandResult b = test::run_command({ONESHOT_SIM_PATH, "dropping", "closed-loop", "--seeds", "8", "--threads", "2",
                                                   "--no-plots", "--out", dir + "/dropping", "--json", dir + "/dropping.json"}, o);
  ASSERT_EQ(b.exit_code, 0) << b.output;
  const nlohmann::json s = nlohmann::json::parse(test::read_file(dir + "/study.json"));
  const nlohmann::json d = nlohmann::json::parse(test::read_file(dir + "/dropping.json"));
  ASSERT_EQ(s.at("per_scenario").size(), d.at("per_lambda").size());
  std::size_t finite = 0;
  for (std::size_t x = 0; x < d.at("per_lambda").size(); ++x) {
    for (const auto& [name, e] : d.at("per_lambda")[x].at("approaches").items()) {
      const nlohmann::json& mine = s.at("per_scenario")[x].at("cost_mean").at(name);
      drop_expect_close(mine, e.at("cost").at("mean"), 1e-12, s.at("per_scenario")[x].at("name").get<std::string>() + " " + name);
      finite += mine.is_null() ? 0U : 1U;
    }
  }
  EXPECT_GE(finite, 6U);  // the buffered filter on both channels in every scenario (the unaware KF diverges)
  // The per-link counters: every sample sent, delivered + lost = sent.
  const nlohmann::json& l = s.at("links").at("buffered").at("sc");
  EXPECT_EQ(l.at("sent").get<double>(), 3.0 * 8 * 1000);
  EXPECT_EQ(l.at("delivered").get<double>() + l.at("lost").get<double>(), l.at("sent").get<double>());
  EXPECT_GT(l.at("late").get<double>(), 0.0);  // over-delayed at T_hold = 1
}

TEST(StudyDropping, SameBytesOnOneAndTwoThreadsAndFromMergedShards) {
  const std::string dir = test::made_dir("oneshot_study_dropping", "bytes");
  const auto run = [&](const std::string& file, std::vector<std::string> extra) {
    std::vector<std::string> argv{ONESHOT_SIM_PATH, "study", "run", file, "--seeds", "5"};
    argv.insert(argv.end(), extra.begin(), extra.end());
    const test::CommandResult r = test::run_command(argv);
    EXPECT_EQ(r.exit_code, 0) << r.output;
  };
  run(kDroppingExample, {"--threads", "1", "--out", dir + "/t1", "--json", dir + "/t1.json"});
  run(kDroppingExample, {"--threads", "2", "--out", dir + "/t2", "--json", dir + "/t2.json"});
  const std::string one = test::read_file(dir + "/t1.json");
  ASSERT_FALSE(one.empty());
  EXPECT_EQ(one, test::read_file(dir + "/t2.json"));
  // Shards hold finite values only (the engine's shard format): the approaches whose loop
  // does not diverge, the plant file by its absolute path.
  nlohmann::json finite = drop_example_json();
  finite["approaches"] = {finite["approaches"][0], finite["approaches"][1]};
  finite["plant"]["file"] = std::string(ONESHOT_STUDY_EXAMPLES_DIR) + "/" + finite["plant"]["file"].get<std::string>();
  const std::string file = dir + "/finite.json";
  util::write_text(file, finite.dump());
  run(file, {"--threads", "1", "--out", dir + "/f1", "--json", dir + "/f1.json"});
  run(file, {"--threads", "1", "--shard", "0/2", "--out", dir + "/sh"});
  run(file, {"--threads", "2", "--shard", "1/2", "--out", dir + "/sh"});
  const test::CommandResult m = test::run_command({ONESHOT_SIM_PATH, "merge", dir + "/sh/run.shard-0-of-2.json",
                                                   dir + "/sh/run.shard-1-of-2.json", "--out", dir + "/m", "--json", dir + "/m.json"});
  ASSERT_EQ(m.exit_code, 0) << m.output;
  const std::string whole = test::read_file(dir + "/f1.json");
  ASSERT_FALSE(whole.empty());
  EXPECT_EQ(whole, test::read_file(dir + "/m.json"));
  EXPECT_EQ(test::read_file(dir + "/f1/runs.csv"), test::read_file(dir + "/m/runs.csv"));
}

/// Per approach the costs of the runs of scenario 0, seeds first … first + 3.
std::vector<double> drop_costs_of(const nlohmann::json& file) {
  const std::shared_ptr<const DroppingStudy> s = drop_map_text(file);
  const engine::SweepResults r = run_dropping_sweep(*s, 4, 1, engine::Shard{});
  std::vector<double> v;
  for (std::size_t a = 0; a < r.spec.approaches.size(); ++a)
    for (std::size_t k = 0; k < 4; ++k) v.push_back(r.at(a, 0, k, r.metric("cost")));
  return v;
}

TEST(StudyDropping, DelayModelsMapOntoTheArrivalStep) {
  // y_k sent at kT arrives at kT + d and is used at step k + ceil(d/T): models with the same
  // arrival step give the same runs bit for bit (the delay stream is apart from the loss stream).
  nlohmann::json base = drop_example_json();
  base["scenarios"] = nlohmann::json::array({{{"name", "one"}}});
  base["approaches"] = nlohmann::json::array({{{"name", "b1"}, {"kind", "buffered"}, {"params", {{"t_hold", 1}}}},
                                              {{"name", "b2"}, {"kind", "buffered"}, {"params", {{"t_hold", 2}}}},
                                              {{"name", "u"}, {"kind", "unaware"}}});
  base["duration_s"] = 2;
  const auto with_delay = [&](const nlohmann::json& delay) {
    nlohmann::json j = base;
    j["links"][0]["delay"] = delay;
    return drop_costs_of(j);
  };
  const auto same = [](const std::vector<double>& a, const std::vector<double>& b, const char* what) {
    ASSERT_EQ(a.size(), b.size());
    for (std::size_t i = 0; i < a.size(); ++i) EXPECT_TRUE(a[i] == b[i] || (std::isnan(a[i]) && std::isnan(b[i]))) << what << " " << i;
  };
  const std::vector<double> next = with_delay({{"model", "poisson_periods"}, {"mean_periods", 0}, {"period_us", 10000}, {"offset_us", 5000}});
  same(next, with_delay({{"model", "constant"}, {"delay_us", 10000}}), "constant T");
  same(next, with_delay({{"model", "uniform"}, {"min_us", 1}, {"max_us", 10000}, {"resolution_us", 1}}), "uniform (0, T]");
  const std::vector<double> two = with_delay({{"model", "constant"}, {"delay_us", 10001}});
  same(two, with_delay({{"model", "uniform"}, {"min_us", 10001}, {"max_us", 20000}, {"resolution_us", 1}}), "uniform (T, 2T]");
  EXPECT_NE(next[0], two[0]);  // a period later is another run
  // Gilbert-Elliott loss and a heavy-tailed delay run (the engine's models, as they are).
  nlohmann::json ge = base;
  ge["links"][0]["loss"] = {{"model", "gilbert_elliott"}, {"p_good_to_bad", 0.05}, {"p_bad_to_good", 0.5}};
  ge["links"][0]["delay"] = {{"model", "lognormal"}, {"median_us", 8000}, {"sigma", 0.5}, {"shift_us", 1000}};
  for (double c : drop_costs_of(ge)) EXPECT_FALSE(std::isnan(c));
}

TEST(StudyDropping, RefusalsNameTheField) {
  struct Case {
    const char* field;
    std::function<void(nlohmann::json&)> edit;
  };
  const std::vector<Case> cases = {
      {"approaches[0].kind", [](nlohmann::json& j) { j["approaches"][0]["kind"] = "smith"; }},
      {"approaches[0].params.t_hold", [](nlohmann::json& j) { j["approaches"][0]["params"]["t_hold"] = 9; }},
      {"approaches[0].params.t_hold", [](nlohmann::json& j) { j["approaches"][0]["params"]["t_hold"] = 1.5; }},
      {"approaches[0].params.r", [](nlohmann::json& j) { j["approaches"][0]["params"]["r"] = 2.5; }},
      {"approaches[2].params.t_hold", [](nlohmann::json& j) { j["approaches"][2]["params"]["t_hold"] = 2; }},
      {"approaches[0].params", [](nlohmann::json& j) { j["approaches"][0]["params"]["q"] = 1; }},
      {"approaches[1].params.lambda", [](nlohmann::json& j) { j["scenarios"][1]["params"].erase("lambda"); }},
      {"links[0].delay",
       [](nlohmann::json& j) {
         j["links"][0]["delay"] = {{"model", "constant"}, {"delay_us", 0}};
         for (nlohmann::json& x : j["scenarios"]) x.erase("links");  // the link's own delay runs
       }},
      {"scenarios[2].links.sc.delay",
       [](nlohmann::json& j) { j["scenarios"][2]["links"]["sc"]["delay"] = {{"model", "uniform"}, {"min_us", 0}, {"max_us", 5}}; }},
      {"plant.file", [](nlohmann::json& j) { j["plant"]["file"] = "../../../lut_gen/plants/networked_board.json"; }},
      {"plant.discrete",
       [](nlohmann::json& j) {
         j["plant"] = {{"discrete", {{"Phi", {{1.25, 1, 0}, {0, 0.9, 7}, {0, 0, 0.6}}}, {"Gamma", {{2.2}, {1}, {0.1}}},
                                     {"C", {{1, 0, 2}}}, {"Q", {{20, 0, 0}, {0, 20, 0}, {0, 0, 20}}}, {"period_us", 10000}}}};
       }},
      {"nodes[2].role",
       [](nlohmann::json& j) {
         j["nodes"].push_back({{"name", "act"}, {"role", "actuator"}, {"address", 3}, {"mode", "timer"}, {"period_us", 10000}});
       }},
      {"nodes[0].period_us", [](nlohmann::json& j) { j["nodes"][0]["period_us"] = 20000; }},
      {"nodes[1].mode", [](nlohmann::json& j) { j["nodes"][1] = {{"name", "controller"}, {"role", "controller"}, {"address", 2}, {"mode", "arrival"}}; }},
      {"duration_s", [](nlohmann::json& j) { j["duration_s"] = 0.015; }},
      {"reference.kind", [](nlohmann::json& j) { j["reference"] = {{"kind", "steps"}, {"steps", {{0.5, 1}}}}; }},
      {"reference.period_s", [](nlohmann::json& j) { j["reference"] = {{"kind", "square"}, {"amplitude_volts", 1}, {"period_s", 0.015}}; }},
      {"links", [](nlohmann::json& j) { j["links"].push_back({{"name", "cs"}, {"from", "controller"}, {"to", "sensor"}}); }},
      {"links[0].from",
       [](nlohmann::json& j) {
         j["links"][0]["from"] = "controller";
         j["links"][0]["to"] = "sensor";
       }},
  };
  ASSERT_NO_THROW(static_cast<void>(drop_map_text(drop_example_json())));
  for (const Case& c : cases) {
    nlohmann::json j = drop_example_json();
    c.edit(j);
    try {
      static_cast<void>(drop_map_text(j));
      ADD_FAILURE() << c.field << ": accepted";
    } catch (const engine::InputError& e) {
      EXPECT_NE(std::string(e.what()).find("field '" + std::string(c.field)), std::string::npos) << c.field << ": " << e.what();
      EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
    }
  }
}

TEST(StudyDropping, CheckGivesTheDesignAndRunRefusesWhatItCannotRun) {
  const std::string dir = test::made_dir("oneshot_study_dropping", "check");
  test::CommandOptions to_file;
  to_file.stdout_path = dir + "/check.json";
  const test::CommandResult c = test::run_command({ONESHOT_SIM_PATH, "study", "check", kDroppingExample, "--json", "-"}, to_file);
  ASSERT_EQ(c.exit_code, 0) << c.output;
  const nlohmann::json r = nlohmann::json::parse(test::read_file(dir + "/check.json"));
  EXPECT_EQ(r.at("runs_with"), "dropping");
  const nlohmann::json& d = r.at("dropping");
  // λ_sys = 1 − 1/ρ², and λ_c in [λ_sys, 1] (Sinopoli: λ_c ≥ λ_sys).
  const double rho = d.at("rho").get<double>();
  EXPECT_NEAR(d.at("lambda_sys").get<double>(), 1 - 1 / (rho * rho), 1e-15);
  EXPECT_GE(d.at("lambda_c_bracket")[0].get<double>(), d.at("lambda_sys").get<double>());
  EXPECT_LE(d.at("lambda_c_bracket")[1].get<double>() - d.at("lambda_c_bracket")[0].get<double>(), 1e-4);
  EXPECT_EQ(d.at("approaches").size(), 4U);
  for (const char* opt : {"--analytic", "--max-duration"}) {
    std::vector<std::string> argv{ONESHOT_SIM_PATH, "study", "run", kDroppingExample, "--out", dir + "/no", opt};
    if (std::string(opt) == "--max-duration") argv.emplace_back("1");
    const test::CommandResult x = test::run_command(argv);
    EXPECT_NE(x.exit_code, 0);
    EXPECT_NE(x.output.find("field '" + std::string(opt) + "'"), std::string::npos) << x.output;
  }
}

}  // namespace
}  // namespace oneshot::study
