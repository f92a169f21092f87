/// @file cli_engine_test.cpp
/// @brief The engine through the command line: Table I identical for any thread count,
///        shards merged byte for byte, the study grouping, --help at every level.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <unistd.h>

#include "support/run_command.hpp"
#include "support/temp_files.hpp"

namespace oneshot {
namespace {

std::string sim() { return ONESHOT_SIM_PATH; }

std::string fresh_dir(const std::string& name) { return test::fresh_dir("oneshot_engine_cli", name); }

std::string read(const std::string& path) { return test::read_file(path); }

TEST(CliEngine, Table1IsTheSameOnOneAndTwoThreads) {
  const std::string a = fresh_dir("t1");
  const std::string b = fresh_dir("t2");
  for (const auto& [dir, threads] : {std::pair{a, 1}, std::pair{b, 2}}) {
    const auto r = test::run_command(sim() + " table1 --seeds 4 --no-plots --threads " + std::to_string(threads) +
                                     " --out " + dir + " --json " + dir + "/table1.json");
    ASSERT_EQ(r.exit_code, 0) << r.output;
  }
  const std::string ja = read(a + "/table1.json");
  ASSERT_GT(ja.size(), 1000U);
  EXPECT_EQ(ja, read(b + "/table1.json"));
  EXPECT_EQ(read(a + "/table1_runs.csv"), read(b + "/table1_runs.csv"));
  // Wall time and threads live beside the results, never in them.
  EXPECT_EQ(ja.find("wall_time"), std::string::npos);
  const auto timing = nlohmann::json::parse(read(b + "/timing.json"));
  EXPECT_EQ(timing["threads"].get<int>(), 2);
  EXPECT_GT(timing["wall_time_s"].get<double>(), 0);
  const auto j = nlohmann::json::parse(ja);
  EXPECT_TRUE(j["paired_differences"].contains("A-D"));
}

TEST(CliEngine, ShardsMergeToTheSameBytesAsOneRun) {
  const std::string whole = fresh_dir("whole");
  const std::string parts = fresh_dir("parts");
  const std::string merged = fresh_dir("merged");
  auto r = test::run_command(sim() + " table1 --seeds 4 --seed 3 --no-plots --out " + whole + " --json " + whole + "/t.json");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  std::string files;
  for (int i = 0; i < 3; ++i) {
    r = test::run_command(sim() + " table1 --seeds 4 --seed 3 --no-plots --threads 1 --shard " + std::to_string(i) +
                          "/3 --out " + parts);
    ASSERT_EQ(r.exit_code, 0) << r.output;
    files = parts + "/table1.shard-" + std::to_string(i) + "-of-3.json " + files;  // reversed order on purpose
  }
  r = test::run_command(sim() + " merge " + files + " --no-plots --out " + merged + " --json " + merged + "/t.json");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  for (const char* f : {"t.json", "table1_runs.csv", "table1.csv", "table1.md"}) {
    const std::string expected = read(whole + "/" + f);
    ASSERT_FALSE(expected.empty()) << f;
    EXPECT_EQ(read(merged + "/" + f), expected) << f;
  }
  // A missing shard or a shard of another sweep is refused.
  r = test::run_command(sim() + " merge " + parts + "/table1.shard-0-of-3.json " + parts +
                        "/table1.shard-1-of-3.json --no-plots --out " + fresh_dir("m2"));
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.output.find("missing"), std::string::npos) << r.output;
  r = test::run_command(sim() + " table1 --seeds 4 --seed 3 --shard 3/3 --no-plots --out " + fresh_dir("bad"));
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.output.find("--shard"), std::string::npos) << r.output;
}

TEST(CliEngine, StudiesAreGroupedAndTheTopLevelCommandsStay) {
  const std::string a = fresh_dir("group");
  const std::string b = fresh_dir("top");
  auto r1 = test::run_command(sim() + " oneshot table1 --seeds 2 --no-plots --json - --out " + a);
  auto r2 = test::run_command(sim() + " table1 --seeds 2 --no-plots --json - --out " + b);
  ASSERT_EQ(r1.exit_code, 0) << r1.output;
  ASSERT_EQ(r2.exit_code, 0) << r2.output;
  EXPECT_EQ(r1.output, r2.output);
  const auto bare = test::run_command(sim() + " oneshot");
  EXPECT_NE(bare.exit_code, 0);
  for (const char* cmd : {"--help", "oneshot --help", "oneshot table1 --help", "oneshot run --help", "merge --help",
                          "oneshot design --help"}) {
    const auto r = test::run_command(sim() + " " + cmd);
    EXPECT_EQ(r.exit_code, 0) << cmd;
    EXPECT_NE(r.output.find("--help"), std::string::npos) << cmd << ": " << r.output;
  }
  const auto top = test::run_command(sim() + " --help");
  EXPECT_NE(top.output.find("oneshot"), std::string::npos);
  EXPECT_NE(top.output.find("merge"), std::string::npos);
}

}  // namespace
}  // namespace oneshot
