/// @file kernel_cli_test.cpp
/// @brief Task files and `oneshot-sim kernel`: bad files refused with one line naming the
///        field (wcet > period, bcet > wcet, zero period, duplicate names, unknown keys, …);
///        the fixed output keys of analyze and simulate; the Gantt CSV; the study-000
///        experiment's task set (utilization as asked, priority positions).
#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "kernel_experiment.hpp"
#include "oneshot/engine/cpu_analysis.hpp"
#include "oneshot/engine/json_fields.hpp"
#include "support/run_command.hpp"
#include "support/temp_files.hpp"

namespace {

using namespace oneshot;
using namespace oneshot::engine::cpu;

std::string sim() { return ONESHOT_SIM_PATH; }

const char* kGood = R"({"scheduler": "fixed_priority", "context_switch_us": 0,
  "tasks": [{"name": "a", "period_us": 7, "wcet_us": 3, "bcet_us": 3, "priority": 1},
            {"name": "b", "period_us": 12, "wcet_us": 3, "bcet_us": 2, "priority": 2},
            {"name": "c", "period_us": 20, "wcet_us": 5, "bcet_us": 5, "priority": 3}],
  "isrs": []})";

/// The error message of parsing `text` ("" when it parses).
std::string error_of(const std::string& text) {
  try {
    parse_task_set(text, "t.json", ".");
  } catch (const engine::InputError& e) {
    return e.what();
  }
  return "";
}

std::string with(const std::string& from, const std::string& to) {
  std::string s = kGood;
  const auto p = s.find(from);
  EXPECT_NE(p, std::string::npos) << from;
  return s.replace(p, from.size(), to);
}

TEST(KernelTaskFile, BadFilesNameTheField) {
  EXPECT_EQ(error_of(kGood), "");
  EXPECT_EQ(error_of(with(R"("period_us": 7, "wcet_us": 3)", R"("period_us": 7, "wcet_us": 8)")),
            "t.json: field 'tasks[0].wcet_us': exceeds period_us");
  EXPECT_EQ(error_of(with(R"("wcet_us": 3, "bcet_us": 2)", R"("wcet_us": 3, "bcet_us": 4)")),
            "t.json: field 'tasks[1].bcet_us': exceeds wcet_us");
  EXPECT_NE(error_of(with(R"("period_us": 20)", R"("period_us": 0)")).find("field 'tasks[2].period_us'"), std::string::npos);
  EXPECT_EQ(error_of(with(R"("name": "b")", R"("name": "a")")), "t.json: field 'tasks[1].name': duplicate name 'a'");
  EXPECT_NE(error_of(with(R"("priority": 3})", R"("priority": 3, "colour": 1})")).find("field 'tasks[2].colour': unknown field"),
            std::string::npos);
  EXPECT_NE(error_of(with(R"("context_switch_us": 0)", R"("context_switch_us": 0, "cpus": 1)")).find("field 'cpus': unknown"),
            std::string::npos);
  EXPECT_NE(error_of(with("fixed_priority", "round_robin")).find("field 'scheduler'"), std::string::npos);
  EXPECT_NE(error_of(with(R"("isrs": [])", R"("isrs": [{"name": "c", "period_us": 9, "cost_us": 1, "priority": 1}])"))
                .find("field 'isrs[0].name': duplicate name 'c'"),
            std::string::npos);
  EXPECT_NE(error_of(with(R"("wcet_us": 5, "bcet_us": 5, "priority": 3})",
                               R"("exec": {"model": "uniform", "bcet_us": 4, "wcet_us": 2}, "priority": 3})"))
                .find("field 'tasks[2].exec.bcet_us': exceeds wcet_us"),
            std::string::npos);
}

TEST(KernelTaskFile, ExecModels) {
  const TaskSet s = parse_task_set(
      R"({"scheduler": "edf", "tasks": [
        {"name": "h", "period_us": 1000, "priority": 1, "exec": {"model": "histogram", "values_us": [10, 30], "weights": [1, 3]}},
        {"name": "i", "period_us": 1000, "priority": 2, "exec": {"model": "instructions", "clock_mips": 40, "instructions_min": 4000, "instructions_max": 4400}}]})",
      "m.json", ".");
  EXPECT_EQ(s.tasks[0].exec.bcet, engine::from_us(10));
  EXPECT_EQ(s.tasks[0].exec.wcet, engine::from_us(30));
  EXPECT_EQ(s.tasks[1].exec.bcet, engine::from_us(100));  // 4000 instructions at 40 MIPS
  EXPECT_EQ(s.tasks[1].exec.wcet, engine::from_us(110));
}

TEST(KernelCli, BadFileExitsNonZeroWithOneLine) {
  const std::string dir = test::made_dir("oneshot_kernel_cli", "bad");
  const std::string f = dir + "/bad.json";
  std::ofstream(f) << with(R"("wcet_us": 3, "bcet_us": 2)", R"("wcet_us": 3, "bcet_us": 4)");
  for (const char* cmd : {"analyze", "simulate"}) {
    std::vector<std::string> argv = {sim(), "kernel", cmd, "--tasks", f, "--json", "-"};
    if (std::string(cmd) == "simulate") argv.insert(argv.end(), {"--duration", "1"});
    const auto r = test::run_command(argv);
    EXPECT_NE(r.exit_code, 0);
    EXPECT_EQ(r.output, "oneshot-sim: error: " + f + ": field 'tasks[1].bcet_us': exceeds wcet_us\n");
  }
}

TEST(KernelCli, AnalyzeAndSimulateKeys) {
  const std::string dir = test::made_dir("oneshot_kernel_cli", "ok");
  const std::string f = dir + "/good.json";
  std::ofstream(f) << kGood;
  const auto a = test::run_command({sim(), "kernel", "analyze", "--tasks", f, "--json", dir + "/a.json"});
  ASSERT_EQ(a.exit_code, 0) << a.output;
  const nlohmann::json ja = nlohmann::json::parse(test::read_file(dir + "/a.json"));
  EXPECT_TRUE(ja.at("schedulable").get<bool>());
  EXPECT_EQ(ja.at("tasks").at(2).at("name"), "c");
  EXPECT_EQ(ja.at("tasks").at(2).at("wcrt_us").get<double>(), 20.0);  // Burns & Wellings
  EXPECT_TRUE(ja.at("tasks").at(2).contains("bcrt_us"));
  const auto s = test::run_command({sim(), "kernel", "simulate", "--tasks", f, "--duration", "0.001", "--seed", "3",
                                    "--json", dir + "/s.json", "--out", dir, "--no-plots"});
  ASSERT_EQ(s.exit_code, 0) << s.output;
  const nlohmann::json js = nlohmann::json::parse(test::read_file(dir + "/s.json"));
  EXPECT_EQ(js.at("tasks").at(2).at("response_max_us").get<double>(), 20.0);
  EXPECT_EQ(js.at("tasks").at(2).at("deadline_misses").get<int>(), 0);
  EXPECT_NEAR(js.at("utilization").get<double>(), 3.0 / 7 + 3.0 / 12 + 5.0 / 20, 1e-12);
  EXPECT_NE(test::read_file(dir + "/gantt.csv").find("row,start_ms,end_ms"), std::string::npos);
}

/// EDF: `analyze` gives Spuri's response times under the FP keys (wcrt_us, bcrt_us,
/// jitter_bound_us): A (2, 5) and B (4, 7) have WCRT 4 and 6 (cpu_edf_rta_test.cpp by hand).
/// `simulate` with the low task sampling at its end: its sampling jitter is the closed form's
/// 4 µs (cpu_sampling_test.cpp), at its start 0.
TEST(KernelCli, EdfResponseTimesAndSamplePoint) {
  const std::string dir = test::made_dir("oneshot_kernel_cli", "edf");
  std::ofstream(dir + "/edf.json") << R"({"scheduler": "edf", "tasks": [
    {"name": "A", "period_us": 5, "wcet_us": 2, "priority": 2}, {"name": "B", "period_us": 7, "wcet_us": 4, "priority": 1}]})";
  const auto a = test::run_command({sim(), "kernel", "analyze", "--tasks", dir + "/edf.json", "--json", dir + "/a.json"});
  ASSERT_EQ(a.exit_code, 0) << a.output;
  const nlohmann::json ja = nlohmann::json::parse(test::read_file(dir + "/a.json"));
  EXPECT_EQ(ja.at("tasks").at(0).at("wcrt_us").get<double>(), 4.0);
  EXPECT_EQ(ja.at("tasks").at(1).at("wcrt_us").get<double>(), 6.0);
  EXPECT_EQ(ja.at("tasks").at(0).at("bcrt_us").get<double>(), 2.0);
  EXPECT_EQ(ja.at("tasks").at(0).at("jitter_bound_us").get<double>(), 2.0);
  for (const char* at : {"start", "end"}) {
    std::ofstream(dir + "/fp.json") << R"({"scheduler": "fixed_priority", "tasks": [
      {"name": "hi", "period_us": 5, "wcet_us": 2, "priority": 1},
      {"name": "lo", "period_us": 10, "wcet_us": 4, "bcet_us": 2, "priority": 2, "sample_at": ")" << at << R"("}]})";
    const auto s = test::run_command({sim(), "kernel", "simulate", "--tasks", dir + "/fp.json", "--duration", "0.02", "--json",
                                      dir + "/s.json", "--out", dir, "--no-plots"});
    ASSERT_EQ(s.exit_code, 0) << s.output;
    const nlohmann::json js = nlohmann::json::parse(test::read_file(dir + "/s.json"));
    EXPECT_EQ(js.at("tasks").at(1).at("sampling_jitter_us").get<double>(), std::string(at) == "end" ? 4.0 : 0.0) << at;
  }
}

/// The experiment's sample point reaches the control task; a bad one exits naming the option.
TEST(KernelExperiment, SamplePointOption) {
  sim::KernelExperimentOptions k;
  k.sample_at = parse_job_point_text("0.5", "--sample-at", k.clock_mips);
  const TaskSet s = sim::kernel_task_set(sim::control_job_model(k), 50000, 0.5, sim::ControlPriority::kLowest, k);
  EXPECT_EQ(s.tasks.front().sample_at.kind, JobPoint::Kind::kFraction);
  EXPECT_EQ(s.tasks.front().actuate_at.kind, JobPoint::Kind::kEnd);
  const auto r = test::run_command({sim(), "oneshot", "kernel", "--sample-at", "middle", "--seeds", "2", "--duration", "1"});
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.output.find("--sample-at"), std::string::npos) << r.output;
  const auto o = test::run_command({sim(), "oneshot", "kernel", "--sample-at", "end", "--actuate-at", "start", "--seeds", "2",
                                    "--duration", "1"});
  EXPECT_NE(o.exit_code, 0);
  EXPECT_NE(o.output.find("--actuate-at"), std::string::npos) << o.output;
}

TEST(KernelExperiment, TaskSetHitsUtilizationAndPositions) {
  sim::KernelExperimentOptions k;
  const ExecModel job = sim::control_job_model(k);
  for (double u : {0.3, 0.95}) {
    for (auto p : {sim::ControlPriority::kHighest, sim::ControlPriority::kRateMonotonic, sim::ControlPriority::kLowest}) {
      const TaskSet s = sim::kernel_task_set(job, 50000, u, p, k);
      EXPECT_NEAR(s.utilization(), u, 0.005) << to_string(p);  // wcets rounded to whole µs
      const int expected = p == sim::ControlPriority::kHighest ? 1 : p == sim::ControlPriority::kRateMonotonic ? 6 : 7;
      EXPECT_EQ(s.tasks.front().priority, expected);
      EXPECT_TRUE(analyze(s).tasks.front().bounded);
      // Reads back through the task-file parser.
      EXPECT_EQ(parse_task_set(task_set_json(s).dump(), "x", ".").tasks.size(), s.tasks.size());
    }
  }
}

/// The study-000 experiment, small: every simulated control response and sampling latency
/// within the analysis' WCRT, the unschedulable configuration excluded, and two shards merged
/// into the same table as one run.
TEST(KernelExperiment, SmallSweepWithinBoundsAndShardsMerge) {
  const std::string dir = test::made_dir("oneshot_kernel_cli", "exp");
  const std::vector<std::string> common = {"oneshot", "kernel", "--seeds", "2", "--duration", "2", "--utilizations", "0.3",
                                           "0.95", "--no-plots", "--threads", "1"};
  auto argv = [&](std::vector<std::string> extra) {
    std::vector<std::string> a = {sim()};
    a.insert(a.end(), common.begin(), common.end());
    a.insert(a.end(), extra.begin(), extra.end());
    return a;
  };
  const auto whole = test::run_command(argv({"--out", dir + "/whole", "--json", dir + "/whole.json"}));
  ASSERT_EQ(whole.exit_code, 0) << whole.output;
  const nlohmann::json j = nlohmann::json::parse(test::read_file(dir + "/whole.json"));
  ASSERT_EQ(j.at("configurations").size() + j.at("config").at("excluded").size(), 6U);
  EXPECT_EQ(j.at("config").at("excluded").at(0).at("name"), "U0.95/lowest");
  for (const auto& c : j.at("configurations")) {
    const double wcrt_ms = c.at("control_wcrt_us").get<double>() * 1e-3;
    EXPECT_LE(c.at("response_max_ms").get<double>(), wcrt_ms) << c.at("name");
    EXPECT_LE(c.at("sampling_latency_max_ms").get<double>(), wcrt_ms) << c.at("name");
    EXPECT_TRUE(c.at("ratio_to_A").contains("B"));
  }
  EXPECT_TRUE(j.at("largest_utilization_within_1pct").at("D").contains("lowest"));
  for (const char* shard : {"0/2", "1/2"}) {
    const auto r = test::run_command(argv({"--out", dir + "/shards", "--shard", shard}));
    ASSERT_EQ(r.exit_code, 0) << r.output;
  }
  const auto m = test::run_command({sim(), "merge", dir + "/shards/kernel.shard-0-of-2.json",
                                    dir + "/shards/kernel.shard-1-of-2.json", "--out", dir + "/merged", "--no-plots"});
  ASSERT_EQ(m.exit_code, 0) << m.output;
  EXPECT_EQ(test::read_file(dir + "/merged/kernel.md"), test::read_file(dir + "/whole/kernel.md"));
}

}  // namespace
