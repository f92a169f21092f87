/// @file cli_hardening_test.cpp
/// @brief oneshot-sim under hostile or careless input: no shell, no silent nonsense,
///        every write checked, nothing left behind by a refused or interrupted run.
#include <gtest/gtest.h>

#include <csignal>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <unistd.h>

#include "oneshot/util/child_process.hpp"
#include "support/run_command.hpp"
#include "support/temp_files.hpp"
#include "support/test_plants.hpp"

namespace oneshot {
namespace {

namespace fs = std::filesystem;
using test::run_command;

std::string oneshot_sim() { return ONESHOT_SIM_PATH; }

/// A fresh empty folder `name` (any characters) for one test.
std::string hardening_dir(const std::string& name) { return test::made_dir("oneshot_hard", name); }

/// A scenario file whose only scenario is called `name` (1 s, default jitter).
std::string scenario_named(const std::string& file, const std::string& name) {
  const nlohmann::json j = {{"scenarios", {{{"name", name}, {"duration_s", 1}}}}};
  return test::write_temp_file(file, j.dump());
}

TEST(CliHardening, AScenarioNameIsDataInTheGnuplotScript) {
  if (util::find_program("gnuplot").empty()) GTEST_SKIP() << "gnuplot not installed";
  const std::string dir = hardening_dir("gp_name");
  // gnuplot's command-running function, spelt in two pieces (tests/no_shell.cmake).
  const std::string run = std::string("sys") + "tem";
  // gnuplot runs in the output folder dir/out: ../pwnedN would land in dir.
  const std::string name =
      "x' . " + run + "('touch ../pwned1') . '`touch ../pwned2`\" . " + run + "(\"touch ../pwned3\") . \"";
  const std::string file = scenario_named("hostile_name.json", name);
  const auto r = run_command({oneshot_sim(), "run", "--scenarios", file, "--scenario", name, "--out", dir + "/out"});
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(fs::exists(dir + "/out/run.png"));
  for (const char* f : {"/pwned1", "/pwned2", "/pwned3"}) EXPECT_FALSE(fs::exists(dir + f)) << f;
  EXPECT_NE(test::read_file(dir + "/out/run.gp").find("x'' . " + run + "(''touch ../pwned1'')"), std::string::npos);  // a label
}

TEST(CliHardening, AnOutputFolderWithAnApostropheOrShellSyntaxPlots) {
  if (util::find_program("gnuplot").empty()) GTEST_SKIP() << "gnuplot not installed";
  const std::string base = hardening_dir("gp_folder");
  const std::string out = base + "/it's $(touch " + base + "/pwned) 'x'; touch " + base + "/pwned2";
  const auto r = run_command({oneshot_sim(), "noise", "--duration", "0.5", "--out", out});
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(fs::exists(out + "/noise.png"));
  EXPECT_FALSE(fs::exists(base + "/pwned"));
  EXPECT_FALSE(fs::exists(base + "/pwned2"));
}

TEST(CliHardening, AnOutputFolderIsNotACommandForValgrind) {
#if defined(__SANITIZE_ADDRESS__)
  GTEST_SKIP() << "valgrind cannot run an AddressSanitizer build of oneshot-sim";
#endif
  if (util::find_program("valgrind").empty()) GTEST_SKIP() << "valgrind not installed";
  const std::string base = hardening_dir("vg_folder");
  const std::string out = base + "/a'; touch " + base + "/pwned; echo '%p";
  const auto r = run_command({oneshot_sim(), "exectime", "--no-plots", "--json", "-", "--out", out});
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_FALSE(fs::exists(base + "/pwned"));
  EXPECT_TRUE(fs::exists(out + "/callgrind.half_table.out"));  // '%p' kept literally, not the pid
  const auto j = nlohmann::json::parse(r.output.substr(r.output.find('{')));
  EXPECT_GT(j["variants"]["half_table"]["host_instructions_per_job"].get<double>(), 100.0);
}

struct Refusal {
  std::vector<std::string> args;
  const char* expected;
};

TEST(CliHardening, NonsenseOptionsAreRefusedWithTheReason) {
  const std::string trace = test::write_temp_file("hard_trace.csv", "release_us,exec_us\n1000,300\n");
  const std::vector<Refusal> cases = {
      {{"run", "--duration", "0"}, "--duration: must be in (0, 3600], got 0"},
      {{"run", "--duration", "nan"}, "--duration: must be a finite number, got 'nan'"},
      {{"run", "--duration", "-inf"}, "must be a finite number"},
      {{"noise", "--duration", "nan"}, "must be a finite number, got 'nan'"},
      {{"pil", "--duration", "nan"}, "must be a finite number"},
      {{"gain", "--p0-scale", "nan"}, "--p0-scale: must be a finite number, got 'nan'"},
      {{"gain", "--p0-scale", "0"}, "--p0-scale: must be in (0,"},
      {{"run", "--seed", "-1"}, "--seed: must be an integer in [0, 9007199254740992]"},
      {{"table1", "--seed", "18446744073709551615"}, "--seed: must be an integer"},
      {{"table1", "--threads", "-1"}, "--threads: must be an integer in [0, 1024]"},
      {{"run", "--jitter", "none", "--jitter-trace", trace}, "--jitter-trace needs --jitter trace"},
      {{"run", "--jitter", "uniform", "--jitter-trace", trace}, "--jitter-trace needs --jitter trace"},
      {{"run", "--jitter", "trace", "--jitter-us", "100", "--jitter-trace", trace}, "--jitter-us needs --jitter uniform"},
      {{"run", "--scenarios", "/dev/zero"}, "longer than"},
  };
  for (const Refusal& c : cases) {
    const std::string out = hardening_dir("refused");
    std::vector<std::string> argv = {oneshot_sim()};
    argv.insert(argv.end(), c.args.begin(), c.args.end());
    argv.insert(argv.end(), {"--no-plots", "--out", out + "/o"});
    const auto r = run_command(argv);
    EXPECT_NE(r.exit_code, 0) << c.args[0] << " " << c.args[1] << " " << c.args[2];
    EXPECT_NE(r.output.find(c.expected), std::string::npos) << c.args[1] << " " << c.args[2] << ": " << r.output;
    EXPECT_FALSE(fs::exists(out + "/o")) << "a refused run created its output folder";
  }
}

TEST(CliHardening, AmbiguousOrMalformedInputFilesAreRefusedByName) {
  const std::string dir = hardening_dir("input_files");
  const std::string dup_key =
      test::write_temp_file("hard_dup_key.json", R"({"scenarios": [{"name": "a", "duration_s": 20, "duration_s": 1}]})");
  const std::string dup_name =
      test::write_temp_file("hard_dup_name.json", R"({"scenarios": [{"name": "a"}, {"name": "a", "duration_s": 1}]})");
  const std::string trailing = test::write_temp_file("hard_trailing.csv", "release_us,exec_us\n1000,300 # ms?\n");
  const std::string trace_dir =
      test::write_temp_file("hard_trace_dir.json", R"({"scenarios": [{"name": "a", "jitter": {"model": "trace", "file": ")" +
                                                       dir + R"("}}]})");
  const std::vector<Refusal> cases = {
      {{"run", "--scenarios", dup_key, "--scenario", "a"}, "field 'scenarios[0].duration_s': duplicate key"},
      {{"run", "--scenarios", dup_name, "--scenario", "a"}, "'a' is already the name of scenarios[0]"},
      {{"run", "--jitter", "trace", "--jitter-trace", trailing}, "line 2: expected 'release_us,exec_us'"},
      {{"run", "--scenarios", trace_dir, "--scenario", "a"}, "is a directory, not a jitter trace"},
  };
  for (const Refusal& c : cases) {
    std::vector<std::string> argv = {oneshot_sim()};
    argv.insert(argv.end(), c.args.begin(), c.args.end());
    argv.insert(argv.end(), {"--duration", "0.5", "--no-plots", "--out", dir + "/o"});
    const auto r = run_command(argv);
    EXPECT_NE(r.exit_code, 0) << c.args[2];
    EXPECT_NE(r.output.find(c.expected), std::string::npos) << c.args[2] << ": " << r.output;
    EXPECT_EQ(r.output.find("not valid JSON"), std::string::npos) << r.output;
  }
}

TEST(CliHardening, JitterTraceAloneSelectsTheTraceModel) {
  const std::string trace = test::write_temp_file("hard_trace2.csv", "release_us,exec_us\n1000,300\n2000,300\n");
  const auto r = run_command({oneshot_sim(), "run", "--duration", "0.5", "--jitter-trace", trace, "--no-plots", "--json", "-",
                              "--out", hardening_dir("trace_run")});
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto j = nlohmann::json::parse(r.output);
  EXPECT_NE(j["jitter"].get<std::string>().find("trace " + trace), std::string::npos) << j["jitter"];
}

TEST(CliHardening, ARefusedRunCreatesNoOutputFolder) {
  const std::string overrun = test::write_temp_file(
      "hard_overrun.json",
      R"({"scenarios": [{"name": "late", "jitter": {"model": "uniform", "release_max_us": 49900, "exec_min_us": 300}}]})");
  const std::string base = hardening_dir("refused_run");
  for (const std::vector<std::string>& args :
       {std::vector<std::string>{"table1", "--seeds", "2", "--scenarios", overrun},
        std::vector<std::string>{"run", "--scenarios", overrun, "--scenario", "late"}}) {
    std::vector<std::string> argv = {oneshot_sim()};
    argv.insert(argv.end(), args.begin(), args.end());
    argv.insert(argv.end(), {"--no-plots", "--out", base + "/" + args[0]});
    const auto r = run_command(argv);
    EXPECT_NE(r.exit_code, 0) << args[0];
    EXPECT_NE(r.output.find("overrun"), std::string::npos) << r.output;
    EXPECT_FALSE(fs::exists(base + "/" + args[0])) << args[0];
  }
}

TEST(CliHardening, AFailedWriteIsAnError) {
  for (const std::vector<std::string>& args :
       {std::vector<std::string>{"design", "--json", "/dev/full"},
        std::vector<std::string>{"run", "--duration", "0.5", "--no-plots", "--json", "/dev/full", "--out", hardening_dir("full")}}) {
    std::vector<std::string> argv = {oneshot_sim()};
    argv.insert(argv.end(), args.begin(), args.end());
    const auto r = run_command(argv);
    EXPECT_NE(r.exit_code, 0) << args[0];
    EXPECT_NE(r.output.find("/dev/full: write failed"), std::string::npos) << r.output;
  }
  // Standard output on a full device.
  test::CommandOptions full;
  full.stdout_path = "/dev/full";
  for (const std::vector<std::string>& argv :
       {std::vector<std::string>{oneshot_sim(), "design", "--json", "-"}, std::vector<std::string>{oneshot_sim(), "design"}}) {
    const auto r = run_command(argv, full);
    EXPECT_NE(r.exit_code, 0) << argv.back();
    EXPECT_NE(r.output.find("standard output: write failed"), std::string::npos) << r.output;
  }
}

TEST(CliHardening, AFullDiskAtTheLastFlushIsAnErrorAndLeavesNoPartialFile) {
  // A file size limit makes the disk "full" after 300 bytes. The jobs CSV of a short run
  // (about 2 KB) used to sit in the stream buffer, fail at the final flush unchecked, and
  // leave a truncated file with exit status 0.
  const std::string dir = hardening_dir("fsize");
  test::CommandOptions limited;
  limited.file_size_limit_bytes = 300;
  const std::vector<std::string> run = {oneshot_sim(), "run", "--duration", "0.5", "--trace-step-us", "0", "--no-plots",
                                        "--out", dir + "/o"};
  const auto r = run_command(run, limited);
  EXPECT_NE(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("run_jobs.csv: write failed"), std::string::npos) << r.output;
  std::size_t files = 0;
  if (fs::exists(dir + "/o")) {
    for (const auto& e : fs::recursive_directory_iterator(dir + "/o")) files += e.is_regular_file() ? 1U : 0U;
  }
  EXPECT_EQ(files, 0U) << "neither a truncated file nor a temporary one may stay";
  // The same run without the limit writes the file.
  ASSERT_EQ(run_command(run).exit_code, 0);
  EXPECT_GT(test::read_file(dir + "/o/run_jobs.csv").size(), 300U);
}

TEST(CliHardening, ANonFiniteResultIsAnErrorNotNull) {
  // Spans of ±1e308 V (the cost would overflow to infinity): the design step refuses the
  // field by name (issue 24) instead of reporting a diverged run.
  std::string plant = test::reference_with("/board/pwm_low_volts", "[-1e308]");
  plant = nlohmann::json::parse(plant).dump();
  auto j = nlohmann::json::parse(plant);
  j["board"]["pwm_high_volts"] = {1e308};
  j["board"]["adc_min_volts"] = {-1e308};
  j["board"]["adc_max_volts"] = {1e308};
  const std::string file = test::write_temp_file("hard_span.json", j.dump());
  const auto r = run_command({oneshot_sim(), "run", "--plant", file, "--duration", "0.5", "--no-plots", "--json", "-", "--out",
                              hardening_dir("span")});
  EXPECT_NE(r.exit_code, 0) << r.output;
  EXPECT_EQ(r.output.find("null"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("board.pwm_low_volts[0]"), std::string::npos) << r.output;
}

TEST(CliHardening, ReportWritesWhereOutSays) {
  const std::string cwd = hardening_dir("report_cwd");
  const std::string out = hardening_dir("report_out") + "/r";
  // Both forms given and different: refused.
  const auto both = run_command({oneshot_sim(), "report", out, "--out", out + "2"});
  EXPECT_NE(both.exit_code, 0);
  EXPECT_NE(both.output.find("two output folders given"), std::string::npos) << both.output;
  // --out alone: the first experiment's files appear there, nothing in ./out.
  test::CommandOptions in_cwd;
  in_cwd.working_dir = cwd;
  test::BackgroundCommand report({oneshot_sim(), "report", "--out", out, "--no-mcu", "--no-plots", "--seeds", "2"}, in_cwd);
  EXPECT_TRUE(test::eventually([&] { return fs::exists(out + "/noise_trace.csv"); }, 60'000));
  ::kill(report.pid(), SIGTERM);
  const auto r = report.wait(10'000);
  EXPECT_EQ(r.signal, SIGTERM) << r.output;
  EXPECT_FALSE(fs::exists(cwd + "/out"));
}

TEST(CliHardening, AShardFileIsReadStrictlyAndBounded) {
  const std::string dir = hardening_dir("shards");
  // A valid shard of a two-seed table1, then the same file with a key given twice.
  const std::string one = scenario_named("hard_shard_scenario.json", "short");
  const auto made = run_command({oneshot_sim(), "table1", "--seeds", "2", "--scenarios", one, "--shard", "0/2", "--no-plots",
                                 "--out", dir});
  ASSERT_EQ(made.exit_code, 0) << made.output;
  const std::string shard = dir + "/table1.shard-0-of-2.json";
  std::string text = test::read_file(shard);
  ASSERT_EQ(text.rfind("{", 0), 0U);
  text.insert(1, "\"format\": \"x\",");
  const std::string twice = test::write_temp_file("hard_shard_twice.json", text);
  for (const std::string& bad : {twice, dir}) {
    const auto r = run_command({oneshot_sim(), "merge", bad, "--no-plots", "--out", dir + "/merged"});
    EXPECT_NE(r.exit_code, 0) << bad;
    EXPECT_NE(r.output.find(bad == dir ? "is a directory" : "duplicate key"), std::string::npos) << r.output;
  }
  EXPECT_FALSE(fs::exists(dir + "/merged"));
}

}  // namespace
}  // namespace oneshot
