/// @file dropping_faults_test.cpp
/// @brief Frame faults in the dropping loop (RunConfig::faults): an empty spec is the clean
///        run bit for bit; NaN, replayed, duplicated and forged samples are refused or dropped
///        and counted by the controller; the buffered loop, and the delay-unaware KFs that
///        run beside it on the same frames (shadows), stay finite within a few times the
///        clean run; every flipped frame is refused as corrupt (its CRC-16); restarts are
///        refused. (The unaware KF closing the loop itself diverges
///        on this plant even clean: it is checked for its counters only.)
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <string>

#include "closed_loop.hpp"
#include "oneshot/engine/fault_spec.hpp"
#include "oneshot/engine/json_fields.hpp"
#include "study_plant.hpp"

namespace {

using namespace oneshot::dropping;
using oneshot::engine::parse_fault_spec;

RunConfig config(EstimatorKind e, const char* spec) {
  RunConfig c;
  c.estimator = e;
  c.steps = 1500;
  c.loss = 0;  // every frame arrives: each fault reaches the controller
  c.faults = parse_fault_spec(spec);
  return c;
}

/// The metrics of a run as one byte string (bit-for-bit comparison).
std::string bits(const RunMetrics& m) {
  const double v[] = {m.trace_p, m.trace_p_anchor, m.err, m.err_anchor, m.err_shadow_small_r, m.err_shadow_nominal_r,
                      m.gamma, m.cost, m.corrections, m.over_delayed, m.duplicates, m.reordered};
  return std::string(reinterpret_cast<const char*>(v), sizeof v);
}

/// The buffered loop's own figures (not the packet counters, not the shadows) as bytes.
std::string loop_bits(const RunMetrics& m) {
  const double v[] = {m.trace_p, m.trace_p_anchor, m.err, m.err_anchor, m.gamma, m.cost, m.corrections};
  return std::string(reinterpret_cast<const char*>(v), sizeof v);
}

struct Pair {
  RunMetrics faulted, clean;
};

Pair run(EstimatorKind e, const char* spec, std::uint64_t seed = 11) {
  RunConfig c = config(e, spec);
  Pair p{run_closed_loop(study_plant(), c, seed), {}};
  c.faults = {};
  p.clean = run_closed_loop(study_plant(), c, seed);
  return p;
}

/// The buffered loop and its shadows: finite, within 3× the clean run (measured ≤ 1.1×).
void expect_finite_and_bounded(const Pair& p, const char* what) {
  ASSERT_TRUE(std::isfinite(p.clean.cost) && std::isfinite(p.clean.err_shadow_small_r)) << what;
  EXPECT_EQ(p.faulted.estimate_non_finite, 0) << what;
  EXPECT_TRUE(std::isfinite(p.faulted.err)) << what;
  EXPECT_LE(p.faulted.cost, 3 * p.clean.cost) << what;
  EXPECT_LE(p.faulted.err_shadow_small_r, 3 * p.clean.err_shadow_small_r) << what;
  EXPECT_LE(p.faulted.err_shadow_nominal_r, 3 * p.clean.err_shadow_nominal_r) << what;
}

constexpr EstimatorKind kBoth[] = {EstimatorKind::kBuffered, EstimatorKind::kUnaware};

TEST(DroppingFaults, EmptySpecIsTheCleanRunBitForBit) {
  for (EstimatorKind e : kBoth)
    for (ChannelKind ch : {ChannelKind::kNetwork, ChannelKind::kBernoulli}) {
      RunConfig with = config(e, "");
      with.loss = 0.01;
      with.channel = ch;
      RunConfig without = with;
      without.faults = {};
      EXPECT_EQ(bits(run_closed_loop(study_plant(), with, 5)), bits(run_closed_loop(study_plant(), without, 5)));
    }
}

TEST(DroppingFaults, ASpecThatNeverFiresChangesNothing) {
  // Every sample goes through the codec and the frame checks; none is refused.
  for (EstimatorKind e : kBoth) {
    const Pair p = run(e, "nan:at_s=1000");
    EXPECT_EQ(bits(p.faulted), bits(p.clean));
    EXPECT_EQ(p.faulted.refused_non_finite + p.faulted.refused_sequence + p.faulted.stale, 0);
  }
}

TEST(DroppingFaults, NanIsRefusedAndNeverReachesAnEstimate) {
  for (EstimatorKind e : kBoth) {
    const Pair p = run(e, "nan:rate=0.05");
    EXPECT_GT(p.faulted.injected.nan, 50U);
    EXPECT_EQ(p.faulted.refused_non_finite, static_cast<double>(p.faulted.injected.nan));
    if (e == EstimatorKind::kBuffered) expect_finite_and_bounded(p, "nan");
  }
}

TEST(DroppingFaults, ForgedStampsAreRefused) {
  for (EstimatorKind e : kBoth)
    for (const char* spec : {"forge_seq:at_s=2", "forge_seq:rate=0.05"}) {
      const Pair p = run(e, spec);
      EXPECT_GE(p.faulted.injected.forge_seq, 1U) << spec;
      EXPECT_EQ(p.faulted.refused_sequence, static_cast<double>(p.faulted.injected.forge_seq)) << spec;
      if (e == EstimatorKind::kBuffered) expect_finite_and_bounded(p, spec);
    }
}

TEST(DroppingFaults, ReplaysAndDuplicatesAreDropped) {
  // A replayed or duplicated frame carries a genuine (j, y): the buffer drops it (duplicate,
  // over-delayed) or stores the sample it lacked; the unaware KF drops it when the period
  // already holds a newer stamp (stale).
  for (const char* spec : {"replay:age_ms=50,rate=0.05", "dup:rate=0.05"}) {
    const Pair b = run(EstimatorKind::kBuffered, spec);
    const double injected = static_cast<double>(b.faulted.injected.injected());
    EXPECT_GT(injected, 50) << spec;
    EXPECT_GE(b.faulted.duplicates + b.faulted.over_delayed - b.clean.duplicates - b.clean.over_delayed,
              0.9 * injected)
        << spec;  // measured: all but the few that filled a lost sample's slot
    EXPECT_EQ(loop_bits(b.faulted), loop_bits(b.clean)) << spec;
    EXPECT_GE(b.faulted.stale, 0.9 * injected) << spec;
    expect_finite_and_bounded(b, spec);
  }
}

TEST(DroppingFaults, EveryFlippedFrameIsRefusedAsCorrupt) {
  // The Bernoulli channel at λ = 1 delivers every frame half a period later, in order: each
  // flipped frame reaches the controller, and no genuine one is stale.
  for (const char* spec : {"flip:rate=0.05", "flip:bits=2,rate=0.05"})
    for (EstimatorKind e : kBoth) {
      RunConfig c = config(e, spec);
      c.channel = ChannelKind::kBernoulli;
      c.bernoulli_lambda = 1;
      Pair p{run_closed_loop(study_plant(), c, 13), {}};
      c.faults = {};
      p.clean = run_closed_loop(study_plant(), c, 13);
      EXPECT_GT(p.faulted.injected.flip, 50U) << spec;
      EXPECT_EQ(p.faulted.corrupt, static_cast<double>(p.faulted.injected.flip)) << spec;
      if (e != EstimatorKind::kBuffered) continue;  // the unaware loop diverges: its own samples turn non-finite
      EXPECT_EQ(p.faulted.refused_non_finite + p.faulted.refused_sequence + p.faulted.stale, 0) << spec;
      expect_finite_and_bounded(p, spec);
    }
}

TEST(DroppingFaults, RestartsAreRefusedNamingTheNode) {
  for (const char* node : {"sensor", "controller"}) {
    const std::string spec = std::string("restart:node=") + node + ",at_s=1";
    RunConfig c = config(EstimatorKind::kBuffered, spec.c_str());
    try {
      static_cast<void>(run_closed_loop(study_plant(), c, 1));
      ADD_FAILURE() << spec << " was accepted";
    } catch (const oneshot::engine::InputError& e) {
      EXPECT_NE(std::string(e.what()).find(std::string("node '") + node + "' cannot restart"), std::string::npos) << e.what();
    }
  }
  EXPECT_THROW(check_dropping_faults(parse_fault_spec("nan:link=sc,rate=0.1")), oneshot::engine::InputError);
}

}  // namespace
