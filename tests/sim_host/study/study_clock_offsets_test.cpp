/// @file study_clock_offsets_test.cpp
/// @brief Clock offsets of a single-loop ncs file's nodes (sim_host/study/examples/ncs_clock_offsets.json):
///        a node's clock reads t − φ (its timer at kh + φ). The same φ on every node is the loop
///        shifted by φ, its set-point too: the same cost to the bit, every sample φ later; the
///        controller's clock is never read but in differences: the same cost; a sensor φ_s against
///        the actuator's φ_a biases AK's τ_k by exactly φ_s − φ_a (its reports refused exactly when
///        τ_k + φ_s − φ_a > h, each a late period) and moves AKl's sample by exactly that; a trace
///        at phase 0 costs what the sweep's run costs; the refusals name the field or the option.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "ncs_loop.hpp"
#include "oneshot/engine/study_file.hpp"
#include "study_example.hpp"
#include "study_ncs_runner.hpp"
#include "study_ncs_sweep.hpp"

namespace oneshot::study {
namespace {

const test_support::StudyExample kOffsets("ncs_clock_offsets.json");

/// Every approach but the one-shot loops (the example runs I, AK, AKl).
void every_approach(nlohmann::json& j) {
  j["approaches"] = nlohmann::json::array();
  for (const char* k : {"I", "S", "A", "AK", "AKx", "AKl", "SK", "S+", "IK"}) j["approaches"].push_back({{"name", k}, {"kind", k}});
}

/// The example with every approach and the offsets (sensor, controller, actuator) in µs, runs 2 s long.
NcsStudy with_offsets(std::int64_t sensor, std::int64_t controller, std::int64_t actuator) {
  return kOffsets.study(
      [&](nlohmann::json& j) {
        every_approach(j);
        j["nodes"][0]["clock_offset_us"] = sensor;
        j["nodes"][1]["clock_offset_us"] = controller;
        j["nodes"][2]["clock_offset_us"] = actuator;
      },
      2.0);
}

/// The counter `name` of run `r` of approach `a`.
double counter(ncs::Approach a, const ncs::RunResult& r, const std::string& name) {
  const std::vector<std::string> names = ncs::counter_names(a);
  const auto it = std::find(names.begin(), names.end(), name);
  if (it == names.end() || static_cast<std::size_t>(it - names.begin()) >= r.counters.size()) {
    ADD_FAILURE() << "no counter " << name;
    return -1;
  }
  return r.counters[static_cast<std::size_t>(it - names.begin())];
}

TEST(StudyClockOffsets, TheSameOffsetOnEveryNodeShiftsTheLoopItsSetPointToo) {
  // Every event of the loop φ later, the plant's time and the set-point's switches with it
  // (the timer node's φ is the loop's phase): the same cost to the bit, the same draws.
  const NcsStudy s0 = with_offsets(0, 0, 0);
  for (const std::int64_t phi : {1, 1000, 12345, 49999}) {
    const NcsStudy s = with_offsets(phi, phi, phi);
    for (std::size_t a = 0; a < s.approaches.size(); ++a) {
      for (std::size_t k = 0; k < s.scenarios.size(); ++k) {
        for (const std::uint64_t seed : {std::uint64_t{1}, std::uint64_t{7}}) {
          const ncs::RunResult r0 = ncs::run(*s0.ctx, s0.approaches[a], s0.scenarios[k], seed, {});
          const ncs::RunResult r = ncs::run(*s.ctx, s.approaches[a], s.scenarios[k], seed, {});
          const std::string what = std::string(ncs::name(s.approaches[a])) + " phi " + std::to_string(phi);
          EXPECT_EQ(r.cost, r0.cost) << what;  // bit for bit
          EXPECT_EQ(r.late, r0.late) << what;
          EXPECT_EQ(r.counters, r0.counters) << what;
          ASSERT_EQ(r.samples.size(), r0.samples.size()) << what;
          for (std::size_t i = 0; i < r.samples.size(); ++i) {
            // Instants in whole ns: measured error 0 to ~4e-15 s (the doubles' rounding of t).
            EXPECT_NEAR(r.samples[i].t_s - r0.samples[i].t_s, 1e-6 * static_cast<double>(phi), 1e-12) << what;
          }
        }
      }
    }
  }
}

TEST(StudyClockOffsets, TheControllersClockIsReadInDifferencesOnly) {
  // The synchronized controller reads its clock for its own period count (differences) and its
  // commands' stamps (unread); the sampling loops' controller and actuator read none: the same
  // cost to the bit. An actuator's offset in a sampling loop likewise.
  const NcsStudy s0 = with_offsets(0, 0, 0);
  const NcsStudy s = with_offsets(0, 777, 0);
  const NcsStudy sa = with_offsets(0, 0, 31'000);
  for (std::size_t a = 0; a < s.approaches.size(); ++a) {
    const ncs::RunResult r0 = ncs::run(*s0.ctx, s0.approaches[a], s0.scenarios[0], 3, {});
    EXPECT_EQ(ncs::run(*s.ctx, s.approaches[a], s.scenarios[0], 3, {}).cost, r0.cost) << ncs::name(s.approaches[a]);
    if (!ncs::actuation_synchronized(s.approaches[a])) {
      EXPECT_EQ(ncs::run(*sa.ctx, sa.approaches[a], sa.scenarios[0], 3, {}).cost, r0.cost) << ncs::name(s.approaches[a]);
    }
  }
}

TEST(StudyClockOffsets, ASensorOffsetBiasesAksTauByExactlyTheOffset) {
  // AK's sensor samples on the request's arrival a = kh + d_as (d_as whole µs) and reports
  // τ = t_{k+1} − its clock = h − d_as + δ, δ = φ_s − φ_a: the controller refuses τ > h, i.e.
  // exactly the reports with d_as < δ; each leaves its period without a command (late). Without
  // the bias (δ = 0) none is refused: the count is the bias's, to the µs.
  for (const std::int64_t delta : {0, 1000, 2500}) {
    const NcsStudy s = kOffsets.study(
        [&](nlohmann::json& j) {
          j["approaches"] = {{{"name", "I"}, {"kind", "I"}}, {{"name", "AK"}, {"kind", "AK"}}};
          j["nodes"][0]["clock_offset_us"] = delta;
        },
        5.0);
    for (std::size_t k = 0; k < s.scenarios.size(); ++k) {
      ncs::RunOptions o;
      o.noise_free = true;
      o.record_messages = true;
      const ncs::RunResult r = ncs::run(*s.ctx, ncs::Approach::kAK, s.scenarios[k], 11, o);
      std::uint32_t expected = 0;  // requests that arrived less than δ after they were sent
      std::uint32_t requests = 0;
      for (const ncs::MessageEvent& m : r.messages) {
        if (m.leg != "as" || !m.delivered || m.arrival_s > s.scenarios[k].duration_s) continue;
        ++requests;
        if (m.arrival_s - m.sent_s < 1e-6 * static_cast<double>(delta) - 1e-10) ++expected;
      }
      ASSERT_GT(requests, 90u);
      EXPECT_EQ(counter(ncs::Approach::kAK, r, "controller.refused_out_of_range"), expected) << "delta " << delta;
      if (delta == 0) {
        EXPECT_EQ(expected, 0u);
      } else if (delta == 2500) {
        EXPECT_GE(expected, 5u);  // the threshold is crossed (d_as ~ U[0.5, d] ms: 10 or more per scenario measured)
      }
      // Each refused report leaves its period without a command, the only late ones here (the
      // chain's delays stay within h − d_as: none late without the bias); the last period's may
      // fall after the end.
      EXPECT_LE(r.late, expected);
      EXPECT_GE(r.late + 1, expected);
    }
  }
}

TEST(StudyClockOffsets, AklsSensorSamplesLaterByExactlyTheOffset) {
  // AKl's sensor samples at t_k − D on its own clock: at true t_k − D + δ, reporting τ = D
  // (the truth D − δ). Every request arrives before t_k − D (d_as ≤ 4 ms < h − D): every
  // sample δ later than without the offset, the delays the same draws.
  const auto samples = [](std::int64_t delta) {
    const NcsStudy s = kOffsets.study(
        [&](nlohmann::json& j) {
          j["approaches"] = {{{"name", "I"}, {"kind", "I"}}, {{"name", "AKl"}, {"kind", "AKl"}}};
          j["nodes"][0]["clock_offset_us"] = delta;
        },
        3.0);
    ncs::RunOptions o;
    o.noise_free = true;
    return ncs::run(*s.ctx, ncs::Approach::kAKl, s.scenarios[0], 5, o).samples;
  };
  const std::vector<ncs::Point> s0 = samples(0);
  for (const std::int64_t delta : {100, 1000}) {
    const std::vector<ncs::Point> s = samples(delta);
    ASSERT_EQ(s.size(), s0.size());
    ASSERT_GT(s.size(), 50u);
    for (std::size_t i = 0; i < s.size(); ++i) {
      // Measured error 0 to ~4e-15 s (the doubles' rounding of t in whole ns).
      EXPECT_NEAR(s[i].t_s - s0[i].t_s, 1e-6 * static_cast<double>(delta), 1e-12) << i;
    }
  }
}

TEST(StudyClockOffsets, APhaseZeroRunCostsWhatTheRunCosts) {
  // What a trace runs (ncs::at_phase_zero: every offset less the timer node's, some negative).
  const NcsStudy s = with_offsets(1000, 0, 20'000);
  for (std::size_t a = 0; a < s.approaches.size(); ++a) {
    const ncs::Approach ap = s.approaches[a];
    const ncs::Scenario z = ncs::at_phase_zero(s.scenarios[1], ap);
    EXPECT_EQ(ncs::loop_phase_us(ap, z), 0);
    EXPECT_EQ(ncs::run(*s.ctx, ap, z, 2, {}).cost, ncs::run(*s.ctx, ap, s.scenarios[1], 2, {}).cost) << ncs::name(ap);
  }
}

TEST(StudyClockOffsets, WhatDoesNotRunIsRefusedNamingTheFieldOrTheOption) {
  kOffsets.expect_refused([](nlohmann::json& j) { j["nodes"][0]["clock_offset_us"] = 50000; }, "field 'nodes[0].clock_offset_us'");  // = h
  kOffsets.expect_refused([](nlohmann::json& j) { j["nodes"][2]["clock_offset_us"] = -1; }, "field 'nodes[2].clock_offset_us'");
  kOffsets.expect_refused([](nlohmann::json& j) { j["nodes"][1]["clock_offset_us"] = 1.5; }, "field 'nodes[1].clock_offset_us'");
  kOffsets.expect_refused([](nlohmann::json& j) { j["cpus"] = {{{"name", "mcu"}, {"scheduler", "fixed_priority"}}}; },
                          "field 'nodes[0].clock_offset_us'");
  const test_support::StudyExample one_shot("mtm_file_oneshot.json");
  one_shot.expect_refused([](nlohmann::json& j) { j["nodes"][0]["clock_offset_us"] = 100; }, "field 'nodes[0].clock_offset_us'");
  const NcsStudy s = with_offsets(1000, 0, 0);
  try {
    static_cast<void>(run_ncs_sweep(s, 2, 1, engine::Shard{}, true));
    ADD_FAILURE() << "an analytic sweep with clock offsets ran";
  } catch (const engine::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("field '--analytic'"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace oneshot::study
