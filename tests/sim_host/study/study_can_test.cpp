/// @file study_can_test.cpp
/// @brief `study run` with the loop's legs on a CAN bus (sim_host/study/examples/ncs_can.json):
///        without background traffic every message's delay is its transmission time (closed
///        form), with it every delay is within the check's worst-case response time and the
///        mean grows with the background load, the same bytes on 1 and 2 threads and from
///        merged shards, and bad bus references refused naming the field. Several loops on one
///        bus: study_loops_test.cpp.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <functional>
#include <string>

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


const test_support::StudyExample kCan("ncs_can.json");

std::string can_temp_dir(const char* name) { return test::fresh_dir("oneshot_study_can_test", name); }

TEST(StudyCan, WithoutBackgroundEveryDelayIsTheTransmissionTime) {
  const NcsStudy s = kCan.study([](nlohmann::json& j) { j["buses"][0].erase("background"); }, 4);
  const nlohmann::json j = run_outputs(run_ncs_sweep(s, 3, 2, engine::Shard{}), can_temp_dir("quiet"), false);
  // The loop's messages: header (sequence, stamp: 8 bytes) + p = 2 doubles (sc), + m = 1
  // double (ca), + the CRC-16 (2 bytes).
  const double sc_us = message_us(8 + 2 * 8 + 2, 125'000);
  const double ca_us = message_us(8 + 1 * 8 + 2, 125'000);
  EXPECT_EQ(sc_us, (3 * 135 + 75) * 8.0);  // three 8-byte frames of 135 bits and a 2-byte one of 75, 8 us each
  for (const char* a : {"S", "SK"}) {
    for (const auto& [leg, c] : {std::pair<const char*, double>{"sc", sc_us}, {"ca", ca_us}}) {
      const nlohmann::json& e = j.at("bus_delays").at(a).at(leg);
      EXPECT_EQ(e.at("messages").get<double>(), 3 * 2 * 80) << a << " " << leg;  // 3 seeds x 2 scenarios x 4 s / 50 ms
      EXPECT_EQ(e.at("min_us").get<double>(), c) << a << " " << leg;
      EXPECT_EQ(e.at("max_us").get<double>(), c) << a << " " << leg;
      EXPECT_TRUE(e.at("within_bound").get<bool>());
    }
  }
  // I and IK keep their delay-free links: nothing on the bus.
  EXPECT_EQ(j.at("bus_delays").at("I").at("sc").at("messages").get<double>(), 0);
  EXPECT_TRUE(j.at("bus_delays").at("I").at("sc").at("max_us").is_null());
}

TEST(StudyCan, CheckAnalysesTheLoopMessagesInFramesWithTheirChainedJitter) {
  nlohmann::json j = kCan.json();
  j["buses"][0].erase("background");
  const nlohmann::json r = resolve_study(kCan.parse(j));
  const nlohmann::json& m = r.at("buses")[0].at("messages");
  ASSERT_EQ(m.size(), 2U);
  const nlohmann::json& sc = m[0];
  const nlohmann::json& ca = m[1];
  ASSERT_EQ(sc.at("name"), "sc");
  // 125 kbit/s: 8 us a bit, an 8-byte frame 135 bits = 1080 us, a 2-byte one 75 bits =
  // 600 us. sc: 26 bytes, 4 frames, C = 3 × 1080 + 600 = 3840 us; ca: 18 bytes, 3 frames,
  // C = 2 × 1080 + 600 = 2760 us, and the higher priority (id 240 < 256).
  EXPECT_EQ(sc.at("frames"), 4);
  EXPECT_EQ(sc.at("transmission_us").get<double>(), 3840);
  EXPECT_EQ(ca.at("transmission_us").get<double>(), 2760);
  // sc (timer, J = 0, nothing below it: B = 0): its first three frames, one ca message
  // between frames, its last frame: R = (3840 − 600) + 2760 + 600 = 6600 us.
  EXPECT_EQ(sc.at("jitter_us").get<double>(), 0);
  EXPECT_EQ(sc.at("worst_response_us").get<double>(), 6600);
  // ca is sent τ_c ∈ [1, 5] ms after sc arrives, sc's delay in [C, R] = [3840, 6600] us:
  // J = (6600 + 5000) − (3840 + 1000) = 6760 us. Blocked by one sc frame (1080 us), then its
  // frames: R = J + 1080 + 2760 = 10600 us.
  EXPECT_EQ(ca.at("jitter_us").get<double>(), 6760);
  EXPECT_EQ(ca.at("worst_response_us").get<double>(), 10600);
}

/// Mean delay of leg `leg` under S with the background periods multiplied by `scale`, after
/// checking every observed delay against the analysis (`seeds` seeds, 4 s per scenario).
double mean_delay_checked(double scale, const char* leg, std::size_t seeds) {
  const NcsStudy s = kCan.study(
      [scale](nlohmann::json& j) {
        for (auto& b : j["buses"][0]["background"]) b["period_us"] = std::llround(b["period_us"].get<double>() * scale);
      },
      4);
  const nlohmann::json j = run_outputs(run_ncs_sweep(s, seeds, 2, engine::Shard{}), can_temp_dir("load"), false);
  for (const char* a : {"S", "SK"}) {
    for (const char* l : {"sc", "ca"}) {
      const nlohmann::json& e = j.at("bus_delays").at(a).at(l);
      EXPECT_FALSE(e.at("worst_response_us").is_null()) << a << " " << l;
      EXPECT_LE(e.at("max_us").get<double>(), e.at("worst_response_us").get<double>()) << a << " " << l << " scale " << scale;
      EXPECT_TRUE(e.at("within_bound").get<bool>());
      for (const auto& [sc, x] : e.at("per_scenario").items()) {
        EXPECT_LE(x.at("max_us").get<double>(), x.at("worst_response_us").get<double>()) << a << " " << l << " " << sc;
      }
    }
  }
  const nlohmann::json& e = j.at("bus_delays").at("S").at(leg);
  std::printf("background periods x%.2f: S %s delay min %.1f mean %.1f max %.1f us, worst-case response %.1f us\n", scale, leg,
              e.at("min_us").get<double>(), e.at("mean_us").get<double>(), e.at("max_us").get<double>(),
              e.at("worst_response_us").get<double>());
  return e.at("mean_us").get<double>();
}

TEST(StudyCan, WithBackgroundDelaysStayWithinTheBoundAndTheMeanGrowsWithTheLoad) {
  for (const char* leg : {"sc", "ca"}) {
    // 100 seeds per load; a quarter under the sanitizers (the same paths, checked for memory and UB).
    const std::size_t seeds = test::sanitized_length<std::size_t>(100, 4);
    const double light = mean_delay_checked(4, leg, seeds);
    const double file = mean_delay_checked(1, leg, seeds);
    const double heavy = mean_delay_checked(0.5, leg, seeds);
    EXPECT_LT(light, file) << leg;
    EXPECT_LT(file, heavy) << leg;
  }
}

TEST(StudyCan, SameBytesOnOneAndTwoThreadsAndFromMergedShards) {
  test_support::expect_same_bytes_on_threads_and_shards(kCan.study([](nlohmann::json&) {}, 2.5), 4,
                                                        "oneshot_study_can_test", "bus_delays");
}

TEST(StudyCan, BadBusReferencesAreRefusedNamingTheField) {
  kCan.expect_refused([](nlohmann::json& j) { j["links"][0]["bus"] = "can1"; }, "field 'links[0].bus'");  // no such bus
  kCan.expect_refused([](nlohmann::json& j) { j["links"][1]["id"] = 80; }, "field 'links[1].id'");  // the background's
  kCan.expect_refused([](nlohmann::json& j) { j["links"][0]["id"] = 4096; }, "field 'links[0].id'");  // beyond 11 bits
  // A bus leg takes its delay from the bus: delay, loss and order are not its keys (schema).
  kCan.expect_refused([](nlohmann::json& j) { j["links"][0]["delay"] = {{"model", "constant"}, {"delay_us", 100}}; }, "links[0]");
  kCan.expect_refused([](nlohmann::json& j) { j["links"][1]["loss"] = {{"model", "bernoulli"}, {"p", 0.1}}; }, "links[1]");
  kCan.expect_refused([](nlohmann::json& j) { j["scenarios"][0]["links"] = {{"sc", {{"delay", {{"model", "constant"}, {"delay_us", 1}}}}}}; },
                 "scenarios[0].links");
  // What the run cannot do on a bus.
  kCan.expect_refused([](nlohmann::json& j) { j["approaches"].push_back({{"name", "A"}, {"kind", "A"}}); }, "field 'approaches[4].kind'");
  kCan.expect_refused([](nlohmann::json& j) { j["approaches"].push_back({{"name", "S+"}, {"kind", "S+"}}); }, "field 'approaches[4].kind'");
  kCan.expect_refused(
      [](nlohmann::json& j) {
        j["links"].push_back({{"name", "as"}, {"from", "actuator"}, {"to", "sensor"}, {"bus", "can0"}, {"id", 300}});
      },
      "field 'links[2].bus'");
  kCan.expect_refused(
      [](nlohmann::json& j) { j["buses"].push_back({{"name", "spare"}, {"bit_rate", 250000}}); }, "field 'buses[1]'");  // unused
}

}  // namespace
}  // namespace oneshot::study
