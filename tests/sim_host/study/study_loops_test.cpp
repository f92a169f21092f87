/// @file study_loops_test.cpp
/// @brief Several loops on one CAN bus (sim_host/study/examples/two_loops_can.json): apart in
///        time each loop costs what it costs alone, bit for bit (and a loop without a stream
///        prefix what ncs::run gives); together every delay within the check's bound that
///        counts both loops' frames, the second loop's frames delaying the first's; a loop's
///        clock offset shifts the whole loop (alone, the same cost bit for bit) and, between the
///        loops, moves the board's delays within the bound; each loop's NEES that of its runs;
///        the same bytes on 1 and 2 threads and from shards; the loops' refusals naming the field.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <functional>
#include <stdexcept>
#include <string>
#include <tuple>
#include <vector>

#include "oneshot/engine/study_file.hpp"
#include "ncs_loop.hpp"
#include "study_can_frames.hpp"
#include "study_check.hpp"
#include "study_ncs_runner.hpp"
#include "study_ncs_sweep.hpp"
#include "support/build_flavor.hpp"
#include "study_example.hpp"
#include "study_sweep_checks.hpp"
#include "support/temp_files.hpp"

namespace oneshot::study {
namespace {

using test_support::message_us;

std::string loops_temp_dir(const char* name) { return test::fresh_dir("oneshot_study_can_test", name); }

const test_support::StudyExample kTwoLoopsCan("two_loops_can.json");

/// The two-loop example after `edit`, every scenario `duration_s` long, with the check's bounds.
NcsStudy loops_study(const test_support::Edit& edit, double duration_s) {
  nlohmann::json j = kTwoLoopsCan.json();
  edit(j);
  const engine::StudyFile f = kTwoLoopsCan.parse(j);
  NcsStudy s = map_ncs_study(f);
  cap_duration(s, duration_s, "test");
  attach_bus_bounds(s, resolve_study(f));
  return s;
}

/// A point-to-point leg at constant delay `delay_us` (FIFO).
nlohmann::json p2p(const char* name, const char* from, const char* to, int delay_us) {
  return {{"name", name}, {"from", from}, {"to", to}, {"delay", {{"model", "constant"}, {"delay_us", delay_us}}}, {"order", "fifo"}};
}

TEST(StudyLoops, ApartInTimeEachLoopCostsWhatItCostsAlone) {
  // No background. The board's sc on the bus at kh (1620 us: [0, 1.62] ms after a multiple of
  // 50 ms), its ca point to point; the servo's sc point to point at 2 ms, its ca on the bus
  // 2 ms + tau_c (U[1, 5] ms) after kh: within [3, 8.08] ms after a multiple of 10 ms. The bus
  // never holds both loops' frames at once: each loop runs as alone, bit for bit.
  const NcsStudy s = loops_study(
      [](nlohmann::json& j) {
        j["buses"][0].erase("background");
        j["links"][1] = p2p("ca", "board_controller", "board_actuator", 0);
        j["links"][2] = p2p("servo_sc", "servo_sensor", "servo_controller", 2000);
      },
      4);
  ASSERT_EQ(s.loops.size(), 2U);
  const engine::SweepResults r = run_ncs_sweep(s, 3, 2, engine::Shard{});
  for (const char* loop : {"board", "servo"}) {
    const std::size_t shared = r.metric(std::string(loop) + "/cost"), alone = r.metric(std::string(loop) + "/alone.cost");
    for (std::size_t a = 0; a < r.spec.approaches.size(); ++a)
      for (std::size_t x = 0; x < r.spec.scenarios.size(); ++x)
        for (std::size_t k = 0; k < r.spec.seeds; ++k) EXPECT_EQ(r.at(a, x, k, shared), r.at(a, x, k, alone)) << loop << " " << a;
  }
  const nlohmann::json j = run_outputs(r, loops_temp_dir("apart"), false);
  for (const auto& [loop, leg, c_us] : {std::tuple<const char*, const char*, double>{"board", "sc", message_us(26, 250'000)},
                                        {"servo", "ca", message_us(18, 250'000)}}) {  // with the CRC-16
    for (const char* a : {"S", "SK"}) {
      const nlohmann::json& d = j.at("interference").at(loop).at(a).at("bus_delays").at(leg);
      EXPECT_EQ(d.at("shared").at("min_us").get<double>(), c_us) << loop << " " << a;  // the transmission, no queueing
      EXPECT_EQ(d.at("shared").at("max_us").get<double>(), c_us) << loop << " " << a;
      EXPECT_EQ(d.at("shared"), d.at("alone")) << loop << " " << a;
      EXPECT_EQ(j.at("interference").at(loop).at(a).at("shared_minus_alone_mean").get<double>(), 0);
    }
  }
  // A loop without a stream prefix on the shared engine is the loop of ncs::run: same streams.
  ncs::LoopOnBus bare = loops_on_bus(s, 0)[0];
  bare.name.clear();
  for (ncs::Approach a : s.approaches) {
    const ncs::RunResult one = ncs::run(*s.ctx, a, s.scenarios[0], 7, ncs::RunOptions{});
    EXPECT_EQ(ncs::run_loops({bare}, a, 7)[0].cost, one.cost) << ncs::name(a);
  }
}

TEST(StudyLoops, TogetherEveryDelayIsWithinTheBoundCountingBothLoopsAndTheServoDelaysTheBoard) {
  const std::size_t seeds = test::sanitized_length<std::size_t>(10, 3);
  const NcsStudy s = loops_study([](nlohmann::json&) {}, 4);
  const nlohmann::json j = run_outputs(run_ncs_sweep(s, seeds, 2, engine::Shard{}), loops_temp_dir("together"), false);
  for (const char* loop : {"board", "servo"}) {
    for (const char* a : {"S", "SK"}) {
      for (const auto& [leg, d] : j.at("interference").at(loop).at(a).at("bus_delays").items()) {
        ASSERT_FALSE(d.at("worst_response_us").is_null()) << loop << " " << leg;
        EXPECT_LE(d.at("shared").at("max_us").get<double>(), d.at("worst_response_us").get<double>()) << loop << " " << a << " " << leg;
        EXPECT_LE(d.at("alone").at("max_us").get<double>(), d.at("worst_response_us").get<double>()) << loop << " " << a << " " << leg;
        EXPECT_TRUE(d.at("within_bound").get<bool>());
      }
    }
  }
  // The servo's sc (id 200) wins over the board's (256) whenever both sample at once (every
  // 100 ms): the board's frames wait, its mean delay and its cost grow.
  const nlohmann::json& board = j.at("interference").at("board").at("S");
  EXPECT_GT(board.at("bus_delays").at("sc").at("shared").at("mean_us").get<double>(),
            board.at("bus_delays").at("sc").at("alone").at("mean_us").get<double>());
  EXPECT_GT(board.at("bus_delays").at("sc").at("shared").at("max_us").get<double>(),
            board.at("bus_delays").at("sc").at("alone").at("max_us").get<double>());
  EXPECT_GT(board.at("shared_minus_alone_mean").get<double>(), 0);
  // I and IK do not use the bus: the same cost shared and alone.
  for (const char* loop : {"board", "servo"})
    for (const char* a : {"I", "IK"}) EXPECT_EQ(j.at("interference").at(loop).at(a).at("shared_minus_alone_mean").get<double>(), 0);
  // The check's bound of the board's sc counts the servo's frames: larger than with the servo's legs off the bus.
  const auto board_sc_wcrt = [](const nlohmann::json& r) {
    for (const nlohmann::json& m : r.at("buses")[0].at("messages"))
      if (m.at("name") == "sc") return m.at("worst_response_us").get<double>();
    return -1.0;
  };
  nlohmann::json off = kTwoLoopsCan.json();
  off["links"][2] = p2p("servo_sc", "servo_sensor", "servo_controller", 0);
  off["links"][3] = p2p("servo_ca", "servo_controller", "servo_actuator", 0);
  const double with = board_sc_wcrt(resolve_study(kTwoLoopsCan.parse(kTwoLoopsCan.json())));
  const double without = board_sc_wcrt(resolve_study(kTwoLoopsCan.parse(off)));
  EXPECT_GT(with, without);
  EXPECT_GE(with - without, message_us(26, 250'000));  // at least one servo report ahead of it
}

TEST(StudyLoops, AClockOffsetShiftsTheWholeLoopAloneItCostsTheSame) {
  // No background: a loop alone on the bus with its timer, set-point and plant time shifted by
  // φ runs the same arithmetic as at φ = 0 (the plant's intervals are the same integers).
  const NcsStudy s = loops_study([](nlohmann::json& j) { j["buses"][0].erase("background"); }, 4);
  for (std::size_t i = 0; i < s.loops.size(); ++i) {
    for (std::size_t x = 0; x < s.scenarios.size(); ++x) {
      const ncs::LoopOnBus at0 = loops_on_bus(s, x)[i];
      ncs::LoopOnBus shifted = at0;
      shifted.clock_offset_us = i == 0 ? 12'345 : 19'999;  // 0 <= phi < h (50 ms, 20 ms)
      for (ncs::Approach a : s.approaches) {
        const ncs::RunResult r0 = ncs::run_loops({at0}, a, 5)[0], r1 = ncs::run_loops({shifted}, a, 5)[0];
        EXPECT_EQ(r1.cost, r0.cost) << i << " " << x << " " << ncs::name(a);
        EXPECT_EQ(r1.nees, r0.nees) << i << " " << x << " " << ncs::name(a);
        EXPECT_EQ(r1.commands, r0.commands);
        EXPECT_EQ(r1.samples.size(), r0.samples.size());
        ASSERT_FALSE(r1.samples.empty());
        EXPECT_NEAR(r1.samples[0].t_s - r0.samples[0].t_s, 1e-6 * static_cast<double>(shifted.clock_offset_us), 1e-12);  // at kh + phi
        for (std::size_t b = 0; b < r0.bus_legs.size(); ++b) EXPECT_EQ(r1.bus_legs[b].second.max_delay, r0.bus_legs[b].second.max_delay);
      }
    }
  }
  // An offset outside [0, h) is refused by the run.
  ncs::LoopOnBus bad = loops_on_bus(s, 0)[1];
  bad.clock_offset_us = 20'000;
  EXPECT_THROW(static_cast<void>(ncs::run_loops({bad}, ncs::Approach::kS, 1)), std::invalid_argument);
}

const test_support::StudyExample kLoopsPhase("two_loops_can_phase.json");

TEST(StudyLoops, APhaseBetweenTheTimersMovesTheBoardsDelaysWithinTheBound) {
  // two_loops_can_phase.json: the servo's timer at 20k + 5 ms never meets the board's at 50k ms,
  // so the board's report no longer waits behind the servo's; every delay stays within the
  // check's bound (an analysis of every stream released at once: a bound whatever the phases).
  const std::size_t seeds = test::sanitized_length<std::size_t>(6, 2);
  NcsStudy phased = map_ncs_study(kLoopsPhase.parse(kLoopsPhase.json()));
  ASSERT_EQ(phased.loops.size(), 2U);
  EXPECT_EQ(phased.loops[0].clock_offset_us, 0);
  EXPECT_EQ(phased.loops[1].clock_offset_us, 5000);
  cap_duration(phased, 4, "test");
  const nlohmann::json resolved = resolve_study(kLoopsPhase.parse(kLoopsPhase.json()));
  attach_bus_bounds(phased, resolved);
  EXPECT_FALSE(resolved.at("loops")[0].contains("clock_offset_us"));
  EXPECT_EQ(resolved.at("loops")[1].at("clock_offset_us").get<double>(), 5000);  // study check's phase
  const engine::SweepResults rp = run_ncs_sweep(phased, seeds, 2, engine::Shard{});
  EXPECT_EQ(rp.spec.config.at("loops")[1].at("clock_offset_us").get<std::int64_t>(), 5000);
  EXPECT_FALSE(rp.spec.config.at("loops")[0].contains("clock_offset_us"));
  const nlohmann::json jp = run_outputs(rp, loops_temp_dir("phase"), false);
  const nlohmann::json j0 = run_outputs(run_ncs_sweep(loops_study([](nlohmann::json&) {}, 4), seeds, 2, engine::Shard{}),
                                        loops_temp_dir("phase0"), false);
  for (const char* loop : {"board", "servo"})
    for (const char* a : {"S", "SK"})
      for (const auto& [leg, d] : jp.at("interference").at(loop).at(a).at("bus_delays").items()) {
        EXPECT_LE(d.at("shared").at("max_us").get<double>(), d.at("worst_response_us").get<double>()) << loop << " " << leg;
        EXPECT_TRUE(d.at("within_bound").get<bool>()) << loop << " " << leg;
      }
  const auto board_sc = [](const nlohmann::json& j, const char* what) {
    return j.at("interference").at("board").at("S").at("bus_delays").at("sc").at("shared").at(what).get<double>();
  };
  EXPECT_LT(board_sc(jp, "mean_us"), board_sc(j0, "mean_us"));
  EXPECT_LT(board_sc(jp, "max_us"), board_sc(j0, "max_us"));
  // The servo's I and IK use no bus: its offset leaves their cost as it is, bit for bit.
  for (const char* a : {"I", "IK"})
    EXPECT_EQ(jp.at("interference").at("servo").at(a).at("cost_shared_mean"), j0.at("interference").at("servo").at(a).at("cost_shared_mean"));
}

TEST(StudyLoops, EachLoopsNeesIsItsFiltersAsInAFileOfOneLoop) {
  const NcsStudy s = loops_study([](nlohmann::json&) {}, 4);
  const engine::SweepResults r = run_ncs_sweep(s, 2, 2, engine::Shard{});
  const nlohmann::json j = run_outputs(r, loops_temp_dir("nees"), false);
  for (std::size_t i = 0; i < s.loops.size(); ++i) {
    const std::string loop = s.loops[i].loop;
    const nlohmann::json& nees = j.at("loops").at(loop).at("nees");
    EXPECT_FALSE(nees.contains("S"));  // no filter
    for (const char* an : {"SK", "IK"}) {
      const ncs::Approach a = ncs::parse_any_approach(an);
      std::size_t ai = 0;
      while (s.approaches[ai] != a) ++ai;
      double sum = 0;  // the oracle: the runs' own NEES, scenario mean per seed, mean over seeds
      for (std::size_t k = 0; k < 2; ++k)
        for (std::size_t x = 0; x < s.scenarios.size(); ++x) {
          const ncs::RunResult run = ncs::run_loops(loops_on_bus(s, x), a, r.spec.first_seed + k)[i];
          EXPECT_EQ(r.at(ai, x, k, r.metric(loop + "/nees")), run.nees) << loop << " " << an;
          EXPECT_GT(run.nees_steps, 0U);
          sum += run.nees;
        }
      EXPECT_NEAR(nees.at(an).at("nees_mean").get<double>(), sum / 4, 1e-12 * sum) << loop << " " << an;
    }
    EXPECT_GT(nees.at("SK").at("nees_mean").get<double>(), nees.at("IK").at("nees_mean").get<double>());  // SK's input lags its model
  }
  EXPECT_NE(j.at("markdown").get<std::string>().find("NEES"), std::string::npos);
}

TEST(StudyLoops, SameBytesOnOneAndTwoThreadsAndFromMergedShards) {
  test_support::expect_same_bytes_on_threads_and_shards(loops_study([](nlohmann::json&) {}, 2.5), 3,
                                                        "oneshot_study_loops_test", "loops");
}

TEST(StudyLoops, RefusalsNameTheField) {
  const auto& e = kTwoLoopsCan;
  e.expect_refused([](nlohmann::json& j) { j["loops"][1]["sensor"] = "board_sensor"; }, "field 'loops[1].sensor'");  // in two loops
  e.expect_refused([](nlohmann::json& j) { j["loops"][0]["controller"] = "nobody"; }, "field 'loops[0].controller'");  // dangling
  e.expect_refused([](nlohmann::json& j) { j["loops"][0]["sensor"] = "board_controller"; }, "field 'loops[0].sensor'");  // its role
  e.expect_refused([](nlohmann::json& j) { j["loops"][1]["name"] = "board"; }, "field 'loops[1].name'");
  e.expect_refused([](nlohmann::json& j) { j["loops"][0]["period_us"] = 1; }, "field 'loops[0].period_us'");  // unknown key
  e.expect_refused([](nlohmann::json& j) { j["loops"] = nlohmann::json::array(); }, "field 'loops'");
  e.expect_refused([](nlohmann::json& j) { j["plant"] = j["loops"][0]["plant"]; }, "field 'plant'");  // beside loops
  e.expect_refused(
      [](nlohmann::json& j) { j["nodes"].push_back({{"name", "spare"}, {"role", "sensor"}, {"address", 9}, {"period_us", 20000}}); },
      "field 'nodes[6]'");  // in no loop
  e.expect_refused([](nlohmann::json& j) { j["links"][3]["from"] = "board_controller"; }, "field 'links[3].to'");  // across loops
  e.expect_refused([](nlohmann::json& j) { j["loops"][1]["plant"]["file"] = "nowhere.json"; }, "field 'loops[1].plant.file'", true);
  e.expect_refused([](nlohmann::json& j) { j["nodes"][3]["period_us"] = 50000; }, "field 'nodes[3].period_us'");  // not the servo's h
  e.expect_refused(
      [](nlohmann::json& j) {
        j["nodes"][4]["mode"] = "timer";
        j["nodes"][4]["period_us"] = 20000;
      },
      "field 'nodes[4].mode'");  // the servo's controller computes on arrival
  e.expect_refused([](nlohmann::json& j) { j["approaches"].push_back({{"name", "A"}, {"kind", "A"}}); }, "field 'approaches[4].kind'");
  e.expect_refused([](nlohmann::json& j) { j["cpus"] = {{{"name", "mcu"}, {"scheduler", "fixed_priority"}}}; }, "field 'cpus'");
  e.expect_refused(
      [](nlohmann::json& j) { j["links"][2] = {{"name", "servo_x"}, {"from", "servo_sensor"}, {"to", "servo_actuator"}, {"bus", "can0"}, {"id", 200}}; },
      "field 'links[2]'");  // not a leg of the loop
  e.expect_refused([](nlohmann::json& j) { j["links"].erase(3); }, "field 'loops[1]'");  // the servo without its ca
  e.expect_refused([](nlohmann::json& j) { j["nodes"][1]["clock_offset_us"] = 100; }, "field 'nodes[1].clock_offset_us'");  // controller
  e.expect_refused([](nlohmann::json& j) { j["nodes"][5]["clock_offset_us"] = 100; }, "field 'nodes[5].clock_offset_us'");  // actuator
  e.expect_refused([](nlohmann::json& j) { j["nodes"][3]["clock_offset_us"] = 20000; }, "field 'nodes[3].clock_offset_us'");  // = h
  e.expect_refused([](nlohmann::json& j) { j["nodes"][0]["clock_offset_us"] = -1; }, "field 'nodes[0].clock_offset_us'");
  // The run's options.
  const NcsStudy s = loops_study([](nlohmann::json&) {}, 2.5);
  try {
    static_cast<void>(run_ncs_sweep(s, 2, 1, engine::Shard{}, true));
    ADD_FAILURE() << "--analytic accepted";
  } catch (const engine::InputError& x) {
    EXPECT_NE(std::string(x.what()).find("field '--analytic'"), std::string::npos) << x.what();
  }
}

}  // namespace
}  // namespace oneshot::study
