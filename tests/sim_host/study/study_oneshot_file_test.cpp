/// @file study_oneshot_file_test.cpp
/// @brief "study": "oneshot" files (sim_host/study/study_oneshot_*.cpp): the shipped example
///        against `oneshot-sim oneshot table1` on the same scenarios and seeds, its scenarios
///        as Table I's defaults, the same bytes on 1 and 2 threads and from merged shards, the
///        noise-free invariants (no jitter: D is A run for run; a lone constant job on a CPU is
///        the constant jitter model), the CPU schedule's timings within its analysis, and the
///        refusals naming the field.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "oneshot/engine/study_file.hpp"
#include "oneshot/engine/sweep.hpp"
#include "oneshot/util/output_files.hpp"
#include "scenario.hpp"
#include "study_oneshot_study.hpp"
#include "support/run_command.hpp"
#include "support/temp_files.hpp"

namespace oneshot::study {
namespace {

const std::string kOneShotExample = std::string(ONESHOT_STUDY_EXAMPLES_DIR) + "/oneshot.json";
const std::string kOneShotCpuExample = std::string(ONESHOT_STUDY_EXAMPLES_DIR) + "/oneshot_cpu.json";

nlohmann::json os_json(const std::string& path) { return nlohmann::json::parse(test::read_file(path)); }

std::shared_ptr<const OneShotFileStudy> os_map(const nlohmann::json& j, const std::string& as = kOneShotExample) {
  return map_oneshot_study(engine::parse_study(j.dump(), as, &oneshot_schema(), ONESHOT_STUDY_EXAMPLES_DIR));
}

/// Per approach and seed the costs of scenario `x` (`seeds` seeds from the file's first).
std::vector<std::vector<double>> os_costs(const OneShotFileStudy& s, std::size_t x, std::size_t seeds) {
  const engine::SweepResults r = run_oneshot_sweep(s, seeds, 1, engine::Shard{});
  std::vector<std::vector<double>> v(r.spec.approaches.size());
  for (std::size_t a = 0; a < v.size(); ++a)
    for (std::size_t k = 0; k < seeds; ++k) v[a].push_back(r.at(a, x, k, r.metric("cost")));
  return v;
}

TEST(StudyOneShotFile, ExampleScenariosAreTableIDefaults) {
  const std::shared_ptr<const OneShotFileStudy> s = os_map(os_json(kOneShotExample));
  ASSERT_EQ(s->scenarios.size(), 3U);
  for (const sim::Scenario& x : s->scenarios) {
    const sim::Scenario d = sim::find_scenario(sim::default_scenarios(), x.name);
    EXPECT_EQ(x.duration_s, d.duration_s) << x.name;
    EXPECT_EQ(x.amplitude_volts, d.amplitude_volts) << x.name;
    EXPECT_EQ(x.change_period_s, d.change_period_s) << x.name;
    EXPECT_EQ(x.jitter.kind, d.jitter.kind) << x.name;
    EXPECT_EQ(x.jitter.release_min_us, d.jitter.release_min_us) << x.name;
    EXPECT_EQ(x.jitter.release_max_us, d.jitter.release_max_us) << x.name;
    EXPECT_EQ(x.jitter.exec_min_us, d.jitter.exec_min_us) << x.name;
    EXPECT_EQ(x.jitter.exec_max_us, d.jitter.exec_max_us) << x.name;
  }
  EXPECT_EQ(s->kinds, (std::vector<std::string>{"A", "B", "C", "D", "E"}));
}

TEST(StudyOneShotFile, ExampleGivesTheCostsOfTable1) {
  // The example's scenarios (Table I's defaults, by name) as a scenario file for `oneshot table1`.
  const std::string dir = test::made_dir("oneshot_study_oneshot", "oracle");
  nlohmann::json sc = nlohmann::json::array();
  const nlohmann::json example = os_json(kOneShotExample);
  for (const nlohmann::json& x : example.at("scenarios")) {
    const sim::Scenario d = sim::find_scenario(sim::default_scenarios(), x.at("name").get<std::string>());
    sc.push_back({{"name", d.name}, {"duration_s", d.duration_s},
                  {"setpoint", {{"amplitude_volts", d.amplitude_volts}, {"change_period_s", d.change_period_s}}},
                  {"jitter", {{"model", "uniform"}, {"release_min_us", d.jitter.release_min_us}, {"release_max_us", d.jitter.release_max_us},
                              {"exec_min_us", d.jitter.exec_min_us}, {"exec_max_us", d.jitter.exec_max_us}}}});
  }
  nlohmann::json scenario_file;
  scenario_file["scenarios"] = sc;
  util::write_text(dir + "/scenarios.json", scenario_file.dump());
  test::CommandOptions to_file;  // `--json -`: the JSON alone on standard output
  to_file.stdout_path = dir + "/study.json";
  const test::CommandResult a = test::run_command({ONESHOT_SIM_PATH, "study", "run", kOneShotExample, "--seeds", "3", "--threads", "2",
                                                   "--out", dir + "/study", "--json", "-"}, to_file);
  ASSERT_EQ(a.exit_code, 0) << a.output;
  const test::CommandResult b = test::run_command({ONESHOT_SIM_PATH, "oneshot", "table1", "--plant", std::string(ONESHOT_STUDY_EXAMPLES_DIR) +
                                                   "/../../../lut_gen/plants/reference_board.json", "--scenarios", dir + "/scenarios.json",
                                                   "--seeds", "3", "--threads", "2", "--no-plots", "--out", dir + "/table1", "--json",
                                                   dir + "/table1.json"});
  ASSERT_EQ(b.exit_code, 0) << b.output;
  const nlohmann::json s = nlohmann::json::parse(test::read_file(dir + "/study.json"));
  const nlohmann::json t = nlohmann::json::parse(test::read_file(dir + "/table1.json"));
  // Measured: equal to the last bit (the same runs); 1e-12 relative allowed by the brief.
  const auto close = [](const nlohmann::json& x, const nlohmann::json& y, const std::string& what) {
    EXPECT_LE(std::fabs(x.get<double>() - y.get<double>()), 1e-12 * std::fabs(y.get<double>())) << what;
  };
  for (const char* letter : {"A", "B", "C", "D", "E"}) {
    close(s.at("approaches").at(letter).at("cost_mean"), t.at("approaches").at(letter).at("cost_mean"), letter);
    close(s.at("approaches").at(letter).at("cost_ci95"), t.at("approaches").at(letter).at("cost_ci95"), letter);
    close(s.at("approaches").at(letter).at("ratio_to_A"), t.at("approaches").at(letter).at("ratio_to_A"), letter);
    for (std::size_t x = 0; x < 3; ++x)
      close(s.at("per_scenario")[x].at("cost_mean").at(letter), t.at("per_scenario")[x].at("cost_mean").at(letter),
            std::string(letter) + " scenario " + std::to_string(x));
  }
  EXPECT_TRUE(s.contains("paired_differences"));
  EXPECT_EQ(s.at("order_by_mean_cost").size(), 5U);
}

TEST(StudyOneShotFile, SameBytesOnOneAndTwoThreadsAndFromMergedShards) {
  const std::string dir = test::made_dir("oneshot_study_oneshot", "bytes");
  for (const std::string& file : {kOneShotExample, kOneShotCpuExample}) {
    const auto run = [&](std::vector<std::string> extra) {
      std::vector<std::string> argv{ONESHOT_SIM_PATH, "study", "run", file, "--seeds", "3"};
      argv.insert(argv.end(), extra.begin(), extra.end());
      const test::CommandResult r = test::run_command(argv);
      EXPECT_EQ(r.exit_code, 0) << r.output;
    };
    run({"--threads", "1", "--out", dir + "/t1", "--json", dir + "/t1.json"});
    run({"--threads", "2", "--out", dir + "/t2", "--json", dir + "/t2.json"});
    const std::string one = test::read_file(dir + "/t1.json");
    ASSERT_FALSE(one.empty());
    EXPECT_EQ(one, test::read_file(dir + "/t2.json")) << file;
    run({"--threads", "1", "--shard", "0/2", "--out", dir + "/sh"});
    run({"--threads", "2", "--shard", "1/2", "--out", dir + "/sh"});
    const test::CommandResult m = test::run_command({ONESHOT_SIM_PATH, "merge", dir + "/sh/run.shard-0-of-2.json",
                                                     dir + "/sh/run.shard-1-of-2.json", "--out", dir + "/m", "--json", dir + "/m.json"});
    ASSERT_EQ(m.exit_code, 0) << m.output;
    EXPECT_EQ(one, test::read_file(dir + "/m.json")) << file;
    EXPECT_EQ(test::read_file(dir + "/t1/runs.csv"), test::read_file(dir + "/m/runs.csv")) << file;
  }
}

TEST(StudyOneShotFile, WithoutJitterDIsARunForRun) {
  // A is D without the scenario's jitter (approach.hpp): with no jitter (every timing param 0,
  // the model none) their runs are the same, bit for bit.
  nlohmann::json j = os_json(kOneShotExample);
  j["duration_s"] = 4;
  for (nlohmann::json& x : j["scenarios"])
    for (const char* k : {"release_min_us", "release_max_us", "exec_min_us", "exec_max_us"}) x["params"].erase(k);
  const std::shared_ptr<const OneShotFileStudy> s = os_map(j);
  for (const sim::Scenario& x : s->scenarios) EXPECT_EQ(x.jitter.kind, sim::JitterModel::Kind::kNone);
  for (std::size_t x = 0; x < s->scenarios.size(); ++x) {
    const std::vector<std::vector<double>> c = os_costs(*s, x, 3);
    for (std::size_t k = 0; k < 3; ++k) EXPECT_EQ(c[0][k], c[3][k]) << "scenario " << x << " seed " << k;
    // With the example's jitter D differs from A (the check above is not vacuous).
    const std::vector<std::vector<double>> jittered = os_costs(*os_map(os_json(kOneShotExample)), x, 2);
    EXPECT_NE(jittered[0][0], jittered[3][0]);
  }
}

TEST(StudyOneShotFile, LoneConstantJobOnACpuIsTheConstantJitterModel) {
  // The job alone on a CPU without context switches, its execution constant c: every job samples
  // at k h and actuates at k h + c, the timings of the uniform model release 0..0, exec c..c.
  nlohmann::json cpu = os_json(kOneShotCpuExample);
  cpu["duration_s"] = 4;
  cpu["cpus"][0]["tasks"] = nlohmann::json::array();
  cpu["cpus"][0].erase("isrs");
  cpu["cpus"][0]["context_switch_us"] = 0;
  cpu["nodes"][0]["job"] = {{"wcet_us", 450}, {"bcet_us", 450}, {"priority", 1}};
  nlohmann::json model = os_json(kOneShotExample);
  model["duration_s"] = 4;
  model["scenarios"] = cpu["scenarios"];
  for (nlohmann::json& x : model["scenarios"]) {
    x["params"]["exec_min_us"] = 450;
    x["params"]["exec_max_us"] = 450;
  }
  const std::shared_ptr<const OneShotFileStudy> a = os_map(cpu, kOneShotCpuExample), b = os_map(model);
  const sim::Scenario traced = oneshot_run_scenario(*a, 0, 7);
  for (const sim::JobTiming& t : traced.jitter.trace) {
    ASSERT_EQ(t.release_us, 0);
    ASSERT_EQ(t.exec_us, 450);
  }
  for (std::size_t x = 0; x < 2; ++x) {
    const std::vector<std::vector<double>> ca = os_costs(*a, x, 3), cb = os_costs(*b, x, 3);
    for (std::size_t ap = 0; ap < ca.size(); ++ap)
      for (std::size_t k = 0; k < 3; ++k) EXPECT_EQ(ca[ap][k], cb[ap][k]) << "scenario " << x << " approach " << ap << " seed " << k;
  }
}

TEST(StudyOneShotFile, CpuScheduleTimingsWithinItsAnalysis) {
  const std::string dir = test::made_dir("oneshot_study_oneshot", "cpu");
  test::CommandOptions to_file;
  to_file.stdout_path = dir + "/check.json";
  const test::CommandResult c = test::run_command({ONESHOT_SIM_PATH, "study", "check", kOneShotCpuExample, "--json", "-"}, to_file);
  ASSERT_EQ(c.exit_code, 0) << c.output;
  const nlohmann::json r = nlohmann::json::parse(test::read_file(dir + "/check.json"));
  EXPECT_EQ(r.at("runs_with"), "oneshot");
  const nlohmann::json& cpu = r.at("oneshot").at("cpu");
  const double lo = cpu.at("release_us")[0].get<double>(), hi = cpu.at("release_us")[1].get<double>();
  const double wcrt = cpu.at("job_wcrt_us").get<double>(), bcrt = cpu.at("job_bcrt_us").get<double>();
  const std::shared_ptr<const OneShotFileStudy> s = os_map(os_json(kOneShotCpuExample), kOneShotCpuExample);
  std::size_t preempted = 0;
  for (std::uint64_t seed = 1; seed <= 3; ++seed) {
    const sim::Scenario x = oneshot_run_scenario(*s, 0, seed);
    ASSERT_GE(x.jitter.trace.size(), static_cast<std::size_t>(20 / 0.05));
    for (const sim::JobTiming& t : x.jitter.trace) {
      // Whole µs from ns: within 0.5 µs of the analysed bounds (release = sample - kh, finish = sample + exec).
      EXPECT_GE(t.release_us, lo - 0.5);
      EXPECT_LE(t.release_us, hi + 0.5);
      EXPECT_GE(t.release_us + t.exec_us, bcrt - 1);
      EXPECT_LE(t.release_us + t.exec_us, wcrt + 1);
      preempted += t.exec_us > 600 ? 1U : 0U;
    }
  }
  EXPECT_GT(preempted, 0U);  // the ADC interrupt lands in some jobs: execution beyond the job's 600 us
}

TEST(StudyOneShotFile, RefusalsNameTheField) {
  struct Case {
    const char* field;
    std::function<void(nlohmann::json&)> edit;
  };
  const std::vector<Case> cases = {
      {"approaches[0].kind", [](nlohmann::json& j) { j["approaches"][0]["kind"] = "F"; }},
      {"approaches[0].params", [](nlohmann::json& j) { j["approaches"][0]["params"] = {{"number_format", "fixed"}}; }},
      {"approaches[0].params", [](nlohmann::json& j) { j["approaches"][0]["params"] = {{"t_hold", 1}}; }},
      {"scenarios[0].params.release_max_us", [](nlohmann::json& j) { j["scenarios"][0]["params"]["release_max_us"] = 49500; }},
      {"scenarios[0].params.release_max_us",
       [](nlohmann::json& j) {
         j["scenarios"][0]["params"]["release_min_us"] = 3000;
         j["scenarios"][0]["params"]["release_max_us"] = 2000;
       }},
      {"scenarios[1].params.exec_max_us", [](nlohmann::json& j) { j["scenarios"][1]["params"]["exec_max_us"] = 100; }},
      {"scenarios[0].params.exec_min_us", [](nlohmann::json& j) { j["scenarios"][0]["params"]["exec_min_us"] = 1.5; }},
      {"scenarios[2].params.amplitude_volts", [](nlohmann::json& j) { j["scenarios"][2]["params"]["amplitude_volts"] = 50; }},
      {"scenarios[0].params.change_period_s",
       [](nlohmann::json& j) {
         j["scenarios"][0]["params"]["change_period_s"] = 0.001;
         j["scenarios"][0]["duration_s"] = 100000;
       }},
      {"scenarios[0].duration_s", [](nlohmann::json& j) { j["scenarios"][0]["duration_s"] = 0.01; }},
      {"scenarios[0].reference", [](nlohmann::json& j) { j["scenarios"][0]["reference"] = {{"kind", "square"}, {"amplitude_volts", 0.2}, {"period_s", 2}}; }},
      {"reference", [](nlohmann::json& j) { j["reference"] = {{"kind", "square"}, {"amplitude_volts", 0.2}, {"period_s", 2}}; }},
      {"plant.file", [](nlohmann::json& j) { j["plant"]["file"] = "../../../lut_gen/plants/sinopoli_dropping.json"; }},
      {"plant.discrete",
       [](nlohmann::json& j) {
         j["plant"] = {{"discrete", {{"Phi", {{1, 0.1}, {0, 1}}}, {"Gamma", {{0}, {0.1}}}, {"C", {{1, 0}}}, {"Q", {{1, 0}, {0, 1}}}, {"period_us", 50000}}}};
       }},
      {"nodes", [](nlohmann::json& j) { j["nodes"].push_back({{"name", "act"}, {"role", "actuator"}, {"address", 3}, {"mode", "timer"}, {"period_us", 50000}}); }},
      {"nodes[0].role", [](nlohmann::json& j) { j["nodes"][0]["role"] = "sensor"; }},
      {"nodes[0].period_us", [](nlohmann::json& j) { j["nodes"][0]["period_us"] = 25000; }},
      {"nodes[0].mode", [](nlohmann::json& j) { j["nodes"][0] = {{"name", "board"}, {"role", "controller"}, {"address", 1}, {"mode", "arrival"}}; }},
      {"nodes[0].clock_offset_us", [](nlohmann::json& j) { j["nodes"][0]["clock_offset_us"] = 1000; }},
      {"links",
       [](nlohmann::json& j) {
         j["nodes"].push_back({{"name", "s"}, {"role", "sensor"}, {"address", 2}, {"mode", "timer"}, {"period_us", 50000}});
         j["links"] = {{{"name", "sc"}, {"from", "s"}, {"to", "board"}, {"delay", {{"model", "constant"}, {"delay_us", 100}}}}};
       }},
      {"cpus[0]",
       [](nlohmann::json& j) { j["cpus"] = {{{"name", "idle"}, {"tasks", {{{"name", "t"}, {"period_us", 1000}, {"wcet_us", 10}, {"priority", 1}}}}}}; }},
  };
  ASSERT_NO_THROW(static_cast<void>(os_map(os_json(kOneShotExample))));
  for (const Case& c : cases) {
    nlohmann::json j = os_json(kOneShotExample);
    c.edit(j);
    try {
      static_cast<void>(os_map(j));
      ADD_FAILURE() << c.field << ": accepted";
    } catch (const engine::InputError& e) {
      EXPECT_NE(std::string(e.what()).find("field '" + std::string(c.field)), std::string::npos) << c.field << ": " << e.what();
      EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
    }
  }
  // The CPU file: the job's worst-case response at the period, a jitter param beside the CPU.
  const std::vector<Case> cpu_cases = {
      {"nodes[0].job", [](nlohmann::json& j) { j["nodes"][0]["job"] = {{"wcet_us", 49000}, {"bcet_us", 200}, {"priority", 3}}; }},
      {"scenarios[0].params.release_max_us", [](nlohmann::json& j) { j["scenarios"][0]["params"]["release_max_us"] = 1000; }},
      {"nodes[0].job.deadline_us",
       [](nlohmann::json& j) { j["nodes"][0]["job"] = {{"wcet_us", 600}, {"bcet_us", 200}, {"priority", 3}, {"deadline_us", 1000}, {"overrun", "abort"}}; }},
      {"cpus", [](nlohmann::json& j) {
         j["nodes"][0].erase("cpu");
         j["nodes"][0].erase("job");
       }},
  };
  ASSERT_NO_THROW(static_cast<void>(os_map(os_json(kOneShotCpuExample), kOneShotCpuExample)));
  for (const Case& c : cpu_cases) {
    nlohmann::json j = os_json(kOneShotCpuExample);
    c.edit(j);
    try {
      static_cast<void>(os_map(j, kOneShotCpuExample));
      ADD_FAILURE() << c.field << ": accepted";
    } catch (const engine::InputError& e) {
      EXPECT_NE(std::string(e.what()).find("field '" + std::string(c.field)), std::string::npos) << c.field << ": " << e.what();
    }
  }
}

TEST(StudyOneShotFile, CheckGivesTheDesignReportAndBenchRun) {
  const std::string dir = test::made_dir("oneshot_study_oneshot", "check");
  test::CommandOptions to_file;
  to_file.stdout_path = dir + "/check.json";
  const test::CommandResult c = test::run_command({ONESHOT_SIM_PATH, "study", "check", kOneShotExample, "--json", "-"}, to_file);
  ASSERT_EQ(c.exit_code, 0) << c.output;
  const nlohmann::json r = nlohmann::json::parse(test::read_file(dir + "/check.json"));
  EXPECT_EQ(r.at("runs_with"), "oneshot");
  const nlohmann::json& d = r.at("oneshot");
  const double h = d.at("plant").at("period_us").get<double>();
  const nlohmann::json file = os_json(kOneShotExample);
  for (std::size_t x = 0; x < 3; ++x) {  // τ = h − release over the file's release range
    const nlohmann::json& p = file.at("scenarios")[x].at("params");
    EXPECT_EQ(d.at("scenarios")[x].at("tau_one_shot_us")[0].get<double>(), h - p.at("release_max_us").get<double>());
    EXPECT_EQ(d.at("scenarios")[x].at("tau_one_shot_us")[1].get<double>(), h - p.at("release_min_us").get<double>());
  }
  EXPECT_EQ(d.at("approaches").size(), 5U);
  EXPECT_TRUE(d.at("design").contains("L"));
  const test::CommandResult rep = test::run_command({ONESHOT_SIM_PATH, "study", "report", kOneShotExample, dir + "/rep", "--seeds", "2", "--no-plots"});
  ASSERT_EQ(rep.exit_code, 0) << rep.output;
  EXPECT_NE(test::read_file(dir + "/rep/report.md").find("| A | A |"), std::string::npos);
  EXPECT_FALSE(test::read_file(dir + "/rep/table_summary.csv").empty());
  const test::CommandResult bench = test::run_command({ONESHOT_SIM_PATH, "study", "bench", kOneShotExample, "--seeds", "2", "--threads", "1"});
  ASSERT_EQ(bench.exit_code, 0) << bench.output;
  EXPECT_NE(bench.output.find("events"), std::string::npos);
  for (const char* opt : {"--analytic", "--max-duration", "--trace"}) {
    std::vector<std::string> argv{ONESHOT_SIM_PATH, "study", std::string(opt) == "--trace" ? "report" : "run", kOneShotExample};
    argv.push_back(dir + "/no");
    if (std::string(opt) != "--trace") argv.insert(argv.end() - 1, "--out");
    argv.emplace_back(opt);
    if (std::string(opt) == "--max-duration") argv.emplace_back("1");
    if (std::string(opt) == "--trace") argv.emplace_back("A");
    const test::CommandResult x = test::run_command(argv);
    EXPECT_NE(x.exit_code, 0);
    EXPECT_NE(x.output.find("field '" + std::string(opt) + "'"), std::string::npos) << x.output;
  }
}

}  // namespace
}  // namespace oneshot::study
