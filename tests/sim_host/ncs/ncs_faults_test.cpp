/// @file ncs_faults_test.cpp
/// @brief Faults in study `ncs` on the engine: an empty spec, or faults that never fire
///        within the run, leave the run bit-identical to a clean one; a fault spec gives
///        the same run every time and any thread count; duplicates are counted stale one
///        for one; every bit-flipped frame is refused as corrupt (the frames' CRC-16), none
///        used; the fault table command covers every case and is reproducible. The
///        NaN and forged-sequence oracles of issue 24 are kept disabled until the nodes
///        refuse such frames (branch h24nodes): they fail on today's nodes.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "ncs_experiments.hpp"
#include "ncs_faults.hpp"
#include "ncs_loop.hpp"
#include "oneshot/engine/json_fields.hpp"

namespace oneshot::ncs {
namespace {

Scenario faults_scenario() {
  Scenario s = default_scenarios()[1];  // d = 14 ms
  s.duration_s = 4;
  return s;
}

RunResult run_with(const Context& ctx, Approach a, const std::string& spec, std::uint64_t seed = 5) {
  RunOptions o;
  o.faults = engine::parse_fault_spec(spec);
  return run(ctx, a, faults_scenario(), seed, o);
}

TEST(NcsFaults, EmptySpecAndFaultsAfterTheEndAreBitIdenticalToTheCleanRun) {
  const auto ctx = Context::load("");
  for (Approach a : {Approach::kAK, Approach::kS, Approach::kA, Approach::kI}) {
    const RunResult clean = run(*ctx, a, faults_scenario(), 5, RunOptions{});
    for (const char* spec : {"", "nan:at_s=100;flip:rate=0,at_s=100;dup:link=sc,at_s=100;replay:at_s=100;"
                                 "forge_seq:at_s=100;restart:node=sensor,at_s=100;restart:node=actuator,at_s=100"}) {
      const RunResult r = run_with(*ctx, a, spec);
      EXPECT_EQ(r.cost, clean.cost) << name(a) << " '" << spec << "'";  // the fault streams move nothing else
      EXPECT_EQ(r.counters, clean.counters);
      EXPECT_EQ(r.commands, clean.commands);
      EXPECT_EQ(r.injected.injected(), 0u);
    }
  }
}

TEST(NcsFaults, FaultedRunsAreReproducibleAndCounted) {
  const auto ctx = Context::load("");
  const char* spec = "dup:link=sc,rate=0.1;flip:link=ca,rate=0.05;replay:link=as,rate=0.05;restart:node=controller,at_s=2";
  const RunResult a = run_with(*ctx, Approach::kAK, spec);
  const RunResult b = run_with(*ctx, Approach::kAK, spec);
  EXPECT_EQ(a.cost, b.cost);
  EXPECT_EQ(a.counters, b.counters);
  EXPECT_GT(a.injected.dup, 0u);
  EXPECT_GT(a.injected.flip, 0u);
  EXPECT_GT(a.injected.replay, 0u);
  EXPECT_EQ(a.injected.restart, 1u);
  // Every duplicate report reaches the controller right after its original: stale, one for one.
  const RunResult d = run_with(*ctx, Approach::kAK, "dup:link=sc,rate=0.1");
  const auto names = counter_names(Approach::kAK);
  const auto stale = static_cast<std::size_t>(std::find(names.begin(), names.end(), "controller.stale") - names.begin());
  ASSERT_LT(stale, names.size());
  EXPECT_EQ(d.counters[stale], static_cast<double>(d.injected.dup));
  EXPECT_GT(d.injected.dup, 0u);
  // The same sweep with one or two threads gives the same values (streams per source).
  TableOptions t;
  t.seeds = 3;
  t.threads = 1;
  t.approaches = {Approach::kI, Approach::kAK};
  t.scenarios = {faults_scenario()};
  t.faults = engine::parse_fault_spec(spec);
  const auto one = table_sweep(*ctx, t, engine::Shard{});
  t.threads = 2;
  EXPECT_EQ(one.values, table_sweep(*ctx, t, engine::Shard{}).values);
  // Names are checked against the study's links and nodes.
  t.faults = engine::parse_fault_spec("dup:link=xy,rate=0.1");
  EXPECT_THROW(table_sweep(*ctx, t, engine::Shard{}), engine::InputError);
}

// The injector counts the frames it flipped; the receivers' CRC check must refuse every one
// of them (`*.corrupt`), and nothing else may change: no flipped frame is used, so the
// refusal counters of the other causes stay those of the clean run and the cost stays
// finite (5 % of the frames of every leg refused is a lossy loop: its cost is that of the
// loss; the fault table measures the 2 % one-leg case: no loop lost). The legs lose nothing; a flipped frame
// still in flight when the run ends (at most one per leg: the delay is below the period) is
// the only one not counted.
TEST(NcsFaults, EveryFlippedFrameIsRefusedAsCorrupt) {
  const auto ctx = Context::load("");
  for (Approach a : {Approach::kAK, Approach::kS}) {
    const auto names = counter_names(a);
    for (const char* spec : {"flip:rate=0.05", "flip:bits=2,rate=0.05", "flip:bits=3,rate=0.05"}) {
      double flipped = 0;
      for (std::uint64_t seed = 1; seed <= 6; ++seed) {
        const RunResult clean = run(*ctx, a, faults_scenario(), seed, RunOptions{});
        const RunResult r = run_with(*ctx, a, spec, seed);
        double corrupt = 0;
        for (std::size_t i = 0; i < names.size(); ++i) {
          const std::string& n = names[i];
          if (n.size() > 8 && n.compare(n.size() - 8, 8, ".corrupt") == 0) corrupt += r.counters[i];
          if (n.find(".refused_") != std::string::npos) {
            EXPECT_EQ(r.counters[i], clean.counters[i]) << name(a) << " " << spec << " " << n;
          }
        }
        const auto f = static_cast<double>(r.injected.flip);
        flipped += f;
        EXPECT_LE(corrupt, f) << name(a) << " " << spec << " seed " << seed;
        EXPECT_GE(corrupt, f - 3) << name(a) << " " << spec << " seed " << seed;  // zero silent corruption accepted
        EXPECT_TRUE(std::isfinite(r.cost)) << name(a) << " " << spec << " seed " << seed;
      }
      EXPECT_GT(flipped, 40) << name(a) << " " << spec;
    }
  }
}

TEST(NcsFaults, FaultTableCoversEveryCaseReproducibly) {
  const auto ctx = Context::load("");
  FaultTableOptions o;
  o.scenario = faults_scenario();
  o.scenario.duration_s = 3;  // the forged sequences and restarts come at 2 s
  o.seeds = 3;
  o.threads = 1;
  const nlohmann::json j = fault_table(*ctx, o);
  const auto cases = default_fault_cases(Approach::kAK);
  EXPECT_EQ(cases.size(), 18u);  // 5 frame faults × 3 links + 3 restarts
  ASSERT_EQ(j.at("cases").size(), cases.size());
  const std::string md = j.at("markdown").get<std::string>();
  for (const auto& c : cases) EXPECT_NE(md.find("| " + c.name + " |"), std::string::npos) << c.name;
  for (const auto& e : j.at("cases")) {
    const std::string n = e.at("name").get<std::string>();
    if (n.rfind("forge_seq", 0) == 0 || n.rfind("restart", 0) == 0) {
      EXPECT_EQ(e.at("injected_per_run").get<double>(), 1.0) << n;
    }
  }
  o.threads = 2;
  EXPECT_EQ(fault_table(*ctx, o).at("markdown"), md);
}

// Issue 24's oracles: a NaN sample or a forged sequence number costs a finite loop within a
// few times the clean run. They fail on nodes without frame checks (NaN poisons the
// estimate; the forged report makes every later one stale).
TEST(NcsFaults, NanAndForgedSequenceAreAbsorbed) {
  const auto ctx = Context::load("");
  const RunResult clean = run(*ctx, Approach::kAK, faults_scenario(), 5, RunOptions{});
  for (const char* spec : {"nan:link=sc,rate=0.05", "nan:link=ca,rate=0.05", "nan:link=as,rate=0.05",
                           "forge_seq:link=sc,at_s=1", "forge_seq:link=as,at_s=1", "restart:node=actuator,at_s=1"}) {
    const RunResult r = run_with(*ctx, Approach::kAK, spec);
    EXPECT_TRUE(std::isfinite(r.cost)) << spec;
    EXPECT_LT(r.cost, 3 * clean.cost) << spec;
  }
}

}  // namespace
}  // namespace oneshot::ncs
