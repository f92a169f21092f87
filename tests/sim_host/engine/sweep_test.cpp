/// @file sweep_test.cpp
/// @brief Monte Carlo sweeps: the same values for any thread count, shards that merge to
///        exactly the single run (values and summary bytes), refused merges, and the
///        paired statistics against hand computation.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "oneshot/engine/random_stream.hpp"
#include "oneshot/util/child_process.hpp"
#include "oneshot/engine/sweep.hpp"
#include "oneshot/engine/sweep_statistics.hpp"
#include "support/temp_files.hpp"

namespace oneshot::engine {
namespace {

SweepSpec spec() {
  SweepSpec s;
  s.study = "test";
  s.experiment = "toy";
  s.approaches = {"ref", "worse", "noisy"};
  s.scenarios = {"small", "large"};
  s.first_seed = 10;
  s.seeds = 7;
  s.metrics = {"cost", "packets"};
  s.config = {{"horizon", 3}};
  return s;
}

/// A toy run: costs that depend on approach, scenario and the seed's draws (same draws
/// for every approach of a seed: common random numbers).
std::vector<double> toy(std::size_t a, std::size_t s, std::uint64_t seed) {
  RandomStream rng(seed, "noise");
  const double base = (s == 0 ? 1.0 : 10.0) * (1 + 0.1 * rng.normal());
  const double factor = a == 0 ? 1.0 : a == 1 ? 1.5 : 1.0 + 0.3 * rng.normal();
  return {base * factor, static_cast<double>(seed % 5 + a)};
}

TEST(Sweep, ValuesDoNotDependOnTheThreadCount) {
  const SweepResults one = run_sweep(spec(), Shard{}, 1, toy, "t");
  const SweepResults three = run_sweep(spec(), Shard{}, 3, toy, "t");
  EXPECT_TRUE(one.complete());
  EXPECT_EQ(one.values, three.values);
}

TEST(Sweep, ShardsMergeToTheSameBytesAsOneRun) {
  const SweepResults whole = run_sweep(spec(), Shard{}, 2, toy, "t");
  std::vector<SweepResults> shards;
  for (std::size_t i : {2U, 0U, 1U}) {  // any order
    const SweepResults part = run_sweep(spec(), Shard{i, 3}, 1, toy, "t");
    EXPECT_FALSE(part.complete());
    // Through the shard file's text and back, as `merge` reads it.
    shards.push_back(shard_from_json(nlohmann::json::parse(shard_to_json(part).dump(2))));
  }
  const SweepResults merged = merge_shards(shards);
  EXPECT_EQ(merged.values, whole.values);
  const auto sw = summary_json(whole, summarize_metric(whole, 0, 0)).dump(2);
  const auto sm = summary_json(merged, summarize_metric(merged, 0, 0)).dump(2);
  EXPECT_EQ(sw, sm);
}

TEST(Sweep, MergeRefusesMissingRepeatedOrForeignShards) {
  const SweepResults a = run_sweep(spec(), Shard{0, 2}, 1, toy, "t");
  const SweepResults b = run_sweep(spec(), Shard{1, 2}, 1, toy, "t");
  EXPECT_THROW(merge_shards({a}), std::invalid_argument);
  EXPECT_THROW(merge_shards({a, a, b}), std::invalid_argument);
  SweepSpec other = spec();
  other.config["horizon"] = 4;
  const SweepResults c = run_sweep(other, Shard{1, 2}, 1, toy, "t");
  EXPECT_THROW(merge_shards({a, c}), std::invalid_argument);
  EXPECT_NO_THROW(merge_shards({b, a}));
  EXPECT_THROW(parse_shard("3/3"), std::invalid_argument);
  EXPECT_THROW(parse_shard("1/"), std::invalid_argument);
  EXPECT_THROW(parse_shard("-1/2"), std::invalid_argument);
  EXPECT_THROW(parse_shard("1/0"), std::invalid_argument);
  EXPECT_EQ(parse_shard("4/16").index, 4U);
  nlohmann::json bad = shard_to_json(a);
  bad["runs"][0][0] = 1;  // run 1 belongs to shard 1/2
  EXPECT_THROW(shard_from_json(bad), std::invalid_argument);
}

TEST(SweepStatistics, PairedFiguresMatchHandComputation) {
  const SweepResults r = run_sweep(spec(), Shard{}, 1, toy, "t");
  const SweepSummary s = summarize_metric(r, 0, 0);
  const std::size_t k = 3;
  const double m0 = (r.at(0, 0, k, 0) + r.at(0, 1, k, 0)) / 2;
  const double m1 = (r.at(1, 0, k, 0) + r.at(1, 1, k, 0)) / 2;
  EXPECT_NEAR(s.per_seed[1][k], m1, 1e-15 * m1);
  // "worse" is exactly 1.5 × "ref" in every run: ratio 1.5 with zero spread, difference 0.5 m.
  EXPECT_NEAR(s.ratio[1].mean, 1.5, 1e-14);
  EXPECT_NEAR(s.ratio[1].ci95, 0.0, 1e-14);
  EXPECT_NEAR(s.ratio_weighted[1].mean, 1.5, 1e-14);
  double diff = 0;
  for (std::size_t j = 0; j < 7; ++j) diff += (s.per_seed[0][j] - s.per_seed[1][j]) / 7;
  EXPECT_NEAR(s.paired[0].diff.mean, diff, 1e-14);
  EXPECT_EQ(s.paired.size(), 3U);
  EXPECT_LT(m0, m1);
}

TEST(SweepStatistics, SummaryFilesHoldTheRunsAndTheIntervals) {
  const SweepResults r = run_sweep(spec(), Shard{}, 1, toy, "t");
  const SweepSummary s = summarize_metric(r, 0, 0);
  const std::string dir = test::fresh_dir("oneshot_sweep", "files");
  write_summary_files(r, s, dir, "toy", false);
  std::ifstream runs(dir + "/toy_runs.csv");
  std::string header;
  std::getline(runs, header);
  EXPECT_EQ(header, "approach_index,scenario_index,seed,cost,packets");
  std::size_t lines = 0;
  for (std::string l; std::getline(runs, l);) ++lines;
  EXPECT_EQ(lines, r.spec.runs());
  std::ifstream summary(dir + "/toy_summary.csv");
  std::getline(summary, header);
  std::string first;
  std::getline(summary, first);
  char buf[64];
  std::snprintf(buf, sizeof buf, "0,%.9g,%.9g,", s.value[0].mean, s.value[0].ci95);
  EXPECT_EQ(first.rfind(buf, 0), 0U) << first;
}

TEST(SweepStatistics, NamesReachGnuplotAsQuotedStringsNotCommands) {
  if (util::find_program("gnuplot").empty()) GTEST_SKIP() << "gnuplot not installed";
  // Names come from study and shard files. gnuplot's command-running function is spelt in
  // two pieces (tests/no_shell.cmake); gnuplot runs in `dir`, so ../pwnedN would land in root.
  const std::string run = std::string("sys") + "tem";
  SweepSpec sp = spec();
  sp.approaches = {"it's", "x' . " + run + "('touch ../pwned1') . '", "`touch ../pwned2`"};
  sp.metrics = {"cost' . " + run + "('touch ../pwned3') . '", "packets"};
  const SweepResults r = run_sweep(sp, Shard{}, 1, toy, "t");
  const SweepSummary s = summarize_metric(r, 0, 0);
  const std::filesystem::path root = test::fresh_dir("oneshot_sweep", "labels");
  const std::string dir = (root / "out").string();
  write_summary_files(r, s, dir, "toy", true);
  EXPECT_TRUE(std::filesystem::exists(dir + "/toy.png"));
  for (const char* f : {"pwned1", "pwned2", "pwned3"}) EXPECT_FALSE(std::filesystem::exists(root / f)) << f;
  std::ifstream in(dir + "/toy.gp");
  std::stringstream gp;
  gp << in.rdbuf();
  EXPECT_NE(gp.str().find("'x'' . " + run + "(''touch ../pwned1'') . '''"), std::string::npos) << gp.str();
}

TEST(Sweep, ASpecReadBackFromAFileIsBounded) {
  const nlohmann::json j = spec().to_json();
  EXPECT_NO_THROW(SweepSpec::from_json(j));
  // 1000 approaches x 1000 scenarios x 1e7 seeds x 2 metrics would not fit in memory.
  nlohmann::json big = j;
  big["approaches"] = std::vector<std::string>(1000, "a");
  big["scenarios"] = std::vector<std::string>(1000, "s");
  big["seeds"] = 10'000'000;
  EXPECT_THROW(SweepSpec::from_json(big), std::invalid_argument);
  // A metric name becomes a CSV column: no comma, quote or line break.
  for (const char* bad : {"a,b", "a\nb", "a\"b", ""}) {
    nlohmann::json m = j;
    m["metrics"] = {"cost", bad};
    EXPECT_THROW(SweepSpec::from_json(m), std::invalid_argument) << bad;
  }
}

}  // namespace
}  // namespace oneshot::engine
