/// @file sod_faults_test.cpp
/// @brief Frame faults in the send-on-delta run (RunConfig::faults): an empty spec is the
///        clean run bit for bit; NaN, replayed, duplicated and forged frames leave a finite
///        estimate, are counted as injected and as refused by the receiver; every flipped frame
///        is refused as corrupt (its CRC-16); node restarts are refused (the study has no
///        restartable node).
#include <gtest/gtest.h>

#include <cmath>

#include "oneshot/engine/fault_spec.hpp"
#include "oneshot/engine/json_fields.hpp"
#include "sod_model.hpp"
#include "sod_sim.hpp"
#include "study_model.hpp"

namespace {

using namespace oneshot::sod;
using oneshot::engine::parse_fault_spec;

RunConfig config(const char* spec) {
  RunConfig c;
  c.sender = SenderKind::kModifiedSod;
  c.n_t[0] = c.n_t[1] = 50;
  c.steps = 3000;
  c.faults = parse_fault_spec(spec);
  return c;
}

TEST(SodFaults, EmptySpecIsTheCleanRunBitForBit) {
  RunConfig clean = config("");
  clean.loss = 0.1;
  const RunResult a = simulate_run(study_model(), clean, 7);
  RunConfig none;
  none.sender = clean.sender;
  none.n_t[0] = none.n_t[1] = 50;
  none.steps = clean.steps;
  none.loss = clean.loss;
  const RunResult b = simulate_run(study_model(), none, 7);
  for (std::size_t i = 0; i < kNodes; ++i) {
    EXPECT_EQ(a.e[i], b.e[i]);
    EXPECT_EQ(a.sends[i], b.sends[i]);
    EXPECT_EQ(a.lost[i], b.lost[i]);
    EXPECT_EQ(a.detected[i], b.detected[i]);
  }
  EXPECT_EQ(a.nees, b.nees);
  EXPECT_EQ(a.injected.injected(), 0u);
}

TEST(SodFaults, FaultedFramesAreRefusedCountedAndTheEstimateStaysFinite) {
  const RunResult clean = simulate_run(study_model(), config(""), 3);
  struct Case {
    const char* spec;
    bool nan_refused;  // every NaN frame refused as non-finite (no loss: none is lost)
    bool seq_refused;  // every replayed / forged frame refused as out of sequence
  };
  for (const Case& c : {Case{"nan:link=node1,rate=0.05", true, false}, Case{"replay:age_ms=100,rate=0.05", false, true},
                        Case{"forge_seq:link=node2,at_s=5", false, true}, Case{"dup:rate=0.05", false, false}}) {
    const RunResult r = simulate_run(study_model(), config(c.spec), 3);
    EXPECT_GT(r.injected.injected(), 0u) << c.spec;
    for (std::size_t i = 0; i < kNodes; ++i) {
      EXPECT_TRUE(std::isfinite(r.e[i])) << c.spec;
      EXPECT_LT(r.e[i], 3 * clean.e[i]) << c.spec;
    }
    EXPECT_TRUE(std::isfinite(r.nees)) << c.spec;
    EXPECT_EQ(r.estimator_resets, 0) << c.spec;
    if (c.nan_refused) {
      EXPECT_EQ(r.refused_non_finite, static_cast<double>(r.injected.nan)) << c.spec;
    }
    if (c.seq_refused) {
      EXPECT_EQ(r.refused_sequence, static_cast<double>(r.injected.replay + r.injected.forge_seq)) << c.spec;
    }
    if (!c.nan_refused && !c.seq_refused) {
      EXPECT_EQ(r.refused_sequence + r.refused_non_finite, 0) << c.spec;
    }
    EXPECT_EQ(r.corrupt, 0) << c.spec;  // nan and forge_seq re-seal the frame: a wrong sender, not a transfer error
  }
}

TEST(SodFaults, EveryFlippedFrameIsRefusedAsCorrupt) {
  // No loss (ξ = 0), no delay: every flipped frame reaches the receiver.
  const RunResult clean = simulate_run(study_model(), config(""), 5);
  for (const char* spec : {"flip:rate=0.05", "flip:bits=2,rate=0.05"}) {
    const RunResult r = simulate_run(study_model(), config(spec), 5);
    EXPECT_GT(r.injected.flip, 5U) << spec;
    EXPECT_EQ(r.corrupt, static_cast<double>(r.injected.flip)) << spec;
    EXPECT_EQ(r.refused_non_finite + r.refused_sequence, 0) << spec;
    EXPECT_EQ(r.estimator_resets, 0) << spec;
    for (std::size_t i = 0; i < kNodes; ++i) {
      EXPECT_TRUE(std::isfinite(r.e[i])) << spec;
      EXPECT_LT(r.e[i], 3 * clean.e[i]) << spec;
    }
  }
}

TEST(SodFaults, NodeRestartsAndUnknownLinksAreRefused) {
  EXPECT_THROW(simulate_run(study_model(), config("restart:node=node1,at_s=1"), 1), oneshot::engine::InputError);
  EXPECT_THROW(simulate_run(study_model(), config("nan:link=sc,rate=0.1"), 1), oneshot::engine::InputError);
}

}  // namespace
