/// @file study_oneshot_test.cpp
/// @brief `study run` of the one-shot loops (sim_host/study/examples/sod_ge_oneshot.json: a
///        send-on-delta sensor over a Gilbert–Elliott link, OS, OSp, OSK): at δy = 0 without
///        noise the held-value loop OS is the periodic loop OSK bit for bit, the sensor sends
///        fewer samples as δy grows, delivered + lost = sent on the lossy leg, the filter's NEES
///        is near n = 2 when it is consistent (every sample, no loss), the same bytes on 1 and
///        2 threads, and what the loop cannot run is refused naming the field. The one-shot
///        controller's job on a CPU (examples/ncs_cpu_one_shot.json): every τ_c within the
///        analysed [BCRT, WCRT], a lone constant job equal to the loop with that constant τ_c,
///        the timer job analysed as periodic at h, the same bytes on 1 and 2 threads, refusals.
///        The sensor under MTM: at σ = δ = 0, k_max = 1 the periodic loop bit for bit, its
///        reference sends (one per set-point change), refusals, the same bytes on 1 and 2 threads.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <functional>

#include "ncs_cpu.hpp"
#include "ncs_loop.hpp"
#include "oneshot/engine/study_file.hpp"
#include "study_check.hpp"
#include "study_ncs_runner.hpp"
#include "study_ncs_sweep.hpp"
#include "study_cpu_checks.hpp"
#include "study_example.hpp"
#include "support/temp_files.hpp"

namespace oneshot::study {
namespace {

const test_support::StudyExample kOs("sod_ge_oneshot.json");
const test_support::StudyExample kOsCpu("ncs_cpu_one_shot.json");

std::string oneshot_temp_dir(const char* name) { return test::fresh_dir("oneshot_study_os_test", name); }

/// The sensor's thresholds δy (both outputs) and no loss on sc.
std::function<void(nlohmann::json&)> lossless_delta(double delta) {
  return [delta](nlohmann::json& j) {
    j["nodes"][0]["trigger"]["delta"] = {delta, delta};
    j["links"][0].erase("loss");
  };
}

TEST(StudyOneShot, AtZeroDeltaTheHeldValueLoopIsThePeriodicLoop) {
  const NcsStudy s = kOs.study(lossless_delta(0), 4);
  ncs::RunOptions quiet;
  quiet.noise_free = true;
  for (std::size_t x = 0; x < s.scenarios.size(); ++x) {
    for (std::uint64_t seed = 1; seed <= 3; ++seed) {
      // No noise: a silent sensor's held value is its sample (the plant did not move) with
      // R̄ = R + (δy)²/3 = R: the same correction as the sample itself.
      const ncs::RunResult os = ncs::run(*s.ctx, ncs::Approach::kOS, s.scenarios[x], seed, quiet);
      const ncs::RunResult osk = ncs::run(*s.ctx, ncs::Approach::kOSK, s.scenarios[x], seed, quiet);
      EXPECT_EQ(os.cost, osk.cost) << x << " " << seed;
      EXPECT_GT(os.cost, 0);
      EXPECT_LE(os.sent, osk.sent);
      EXPECT_EQ(osk.sent, osk.sampled);
      // With noise every sample moves: δy = 0 sends every one, and the loops are the same.
      const ncs::RunResult n_os = ncs::run(*s.ctx, ncs::Approach::kOS, s.scenarios[x], seed, ncs::RunOptions{});
      const ncs::RunResult n_osk = ncs::run(*s.ctx, ncs::Approach::kOSK, s.scenarios[x], seed, ncs::RunOptions{});
      EXPECT_EQ(n_os.sent, n_os.sampled);
      EXPECT_EQ(n_os.cost, n_osk.cost);
      EXPECT_EQ(n_os.nees, n_osk.nees);
    }
  }
}

TEST(StudyOneShot, EveryPeriodGetsItsCommandWhenTheChainFitsInAPeriod) {
  // Lossless sc, every sample sent (δy = 0): the controller's timer at kh + 20 ms, τ_c ≤ 5 ms and
  // ca ≤ 10 ms put command k+1 at the actuator before (k+1)h, so none is late and the actuator
  // applies one command per period from h on (the first period runs on the initial input).
  const NcsStudy s = kOs.study(lossless_delta(0), 2);
  for (const ncs::Approach a : {ncs::Approach::kOS, ncs::Approach::kOSp, ncs::Approach::kOSK}) {
    for (std::uint64_t seed = 1; seed <= 3; ++seed) {
      const ncs::RunResult r = ncs::run(*s.ctx, a, s.scenarios[0], seed, ncs::RunOptions{});
      const auto periods = static_cast<std::uint32_t>(std::llround(s.scenarios[0].duration_s * 1e6 / s.ctx->period_us()));
      EXPECT_EQ(r.late, 0U) << ncs::name(a) << " " << seed;
      EXPECT_EQ(r.commands, periods - 1) << ncs::name(a) << " " << seed;
    }
  }
  // With δy > 0 the held value is used (R̄ > R) where the sensor stays silent: OS and OSp differ.
  const NcsStudy d = kOs.study(lossless_delta(0.02), 2);
  const ncs::RunResult os = ncs::run(*d.ctx, ncs::Approach::kOS, d.scenarios[0], 1, ncs::RunOptions{});
  const ncs::RunResult osp = ncs::run(*d.ctx, ncs::Approach::kOSp, d.scenarios[0], 1, ncs::RunOptions{});
  EXPECT_LT(os.sent, os.sampled);
  EXPECT_NE(os.cost, osp.cost);
}

TEST(StudyOneShot, SendsFallAsDeltaGrows) {
  double last = 0;
  bool first = true;
  for (double delta : {0.0, 0.005, 0.01, 0.02, 0.05, 0.1}) {
    const NcsStudy s = kOs.study(lossless_delta(delta), 6);
    double sent = 0, sampled = 0;
    for (const ncs::Approach a : {ncs::Approach::kOS, ncs::Approach::kOSp}) {
      for (const ncs::Scenario& x : s.scenarios) {
        for (std::uint64_t seed = 1; seed <= 4; ++seed) {
          const ncs::RunResult r = ncs::run(*s.ctx, a, x, seed, ncs::RunOptions{});
          sent += r.sent;
          sampled += r.sampled;
        }
      }
    }
    if (!first) {
      EXPECT_LT(sent, last) << "delta " << delta;
    }
    EXPECT_LE(sent, sampled);
    last = sent;
    first = false;
  }
}

TEST(StudyOneShot, OnTheLossyLegDeliveredAndLostAddUpToSent) {
  const NcsStudy s = kOs.study([](nlohmann::json&) {}, 6);
  const engine::SweepResults r = run_ncs_sweep(s, 4, 2, engine::Shard{});
  const std::size_t sent = r.metric("sc.sent");
  const std::size_t delivered = r.metric("sc.delivered");
  const std::size_t lost = r.metric("sc.lost");
  double lost_all = 0;
  for (std::size_t a = 0; a < r.spec.approaches.size(); ++a) {
    for (std::size_t x = 0; x < r.spec.scenarios.size(); ++x) {
      for (std::size_t k = 0; k < r.spec.seeds; ++k) {
        EXPECT_EQ(r.at(a, x, k, delivered) + r.at(a, x, k, lost), r.at(a, x, k, sent));
        if (r.spec.approaches[a] == "I" || r.spec.approaches[a] == "IK") {
          EXPECT_EQ(r.at(a, x, k, lost), 0);  // the delay-free references ignore the legs
        } else {
          lost_all += r.at(a, x, k, lost);
        }
      }
    }
  }
  EXPECT_GT(lost_all, 0);
  const nlohmann::json j = run_outputs(r, oneshot_temp_dir("lossy"), false);
  for (const char* a : {"OS", "OSp", "OSK"}) {
    const nlohmann::json& c = j.at("links").at(a).at("sc");
    EXPECT_EQ(c.at("delivered").get<double>() + c.at("lost").get<double>(), c.at("sent").get<double>()) << a;
    EXPECT_EQ(j.at("one_shot").at(a).at("sent").get<double>(), c.at("sent").get<double>()) << a;
  }
  EXPECT_EQ(j.at("one_shot").at("OSK").at("send_rate").get<double>(), 1.0);
  EXPECT_LT(j.at("one_shot").at("OS").at("send_rate").get<double>(), 1.0);
  EXPECT_FALSE(j.at("one_shot").contains("I"));
}

TEST(StudyOneShot, NeesIsNearTheStateDimensionWhenTheFilterIsConsistent) {
  // Every sample, no loss: the filter's model is the loop's (inputs applied at kh, exact Q_d).
  const NcsStudy s = kOs.study(lossless_delta(0.02), 100);
  NcsStudy osk = s;
  osk.approaches = {ncs::Approach::kI, ncs::Approach::kOSK};
  const nlohmann::json j = run_outputs(run_ncs_sweep(osk, 20, 2, engine::Shard{}), oneshot_temp_dir("nees"), false);
  const double nees = j.at("one_shot").at("OSK").at("nees_mean").get<double>();
  const double ci = j.at("one_shot").at("OSK").at("nees_ci95").get<double>();
  // Measured 1.949 ± 0.057 (20 seeds × 2000 steps; the first ~20 steps from P0 = 10 R pull it
  // down by ~1 %): within three intervals of n = 2.
  EXPECT_LT(std::fabs(nees - 2.0), 3 * ci + 0.02) << nees << " ± " << ci;
  EXPECT_LT(ci, 0.2);
}

TEST(StudyOneShot, SameBytesOnOneAndTwoThreads) {
  const NcsStudy s = kOs.study([](nlohmann::json&) {}, 3);
  const std::string one = run_outputs(run_ncs_sweep(s, 3, 1, engine::Shard{}), oneshot_temp_dir("one"), false).dump();
  const std::string two = run_outputs(run_ncs_sweep(s, 3, 2, engine::Shard{}), oneshot_temp_dir("two"), false).dump();
  EXPECT_EQ(one, two);
  EXPECT_TRUE(nlohmann::json::parse(two).contains("one_shot"));
}

TEST(StudyOneShot, WhatTheLoopCannotRunIsRefusedNamingTheField) {
  kOs.expect_refused([](nlohmann::json& j) { j["nodes"][0]["trigger"]["delta"] = {0.02}; }, "field 'nodes[0].trigger.delta'");
  kOs.expect_refused([](nlohmann::json& j) { j["nodes"][0]["trigger"]["delta"] = {0.02, 0.02, 0.02}; },
                 "field 'nodes[0].trigger.delta'");
  // S, SK cannot use a send-on-delta sensor (nor a timer controller).
  kOs.expect_refused([](nlohmann::json& j) { j["approaches"].push_back({{"name", "S"}, {"kind", "S"}}); }, "field 'approaches[5].kind'");
  kOs.expect_refused([](nlohmann::json& j) { j["approaches"].push_back({{"name", "SK"}, {"kind", "SK"}}); }, "field 'approaches[5].kind'");
  // Send-on-delta without a one-shot approach.
  kOs.expect_refused(
      [](nlohmann::json& j) {
        j["approaches"] = nlohmann::json::parse(R"([{"name": "I", "kind": "I"}, {"name": "IK", "kind": "IK"}])");
      },
      "field 'nodes[0].trigger'");
  // OS and OSp need a send-on-delta sensor; OSK does not.
  kOs.expect_refused([](nlohmann::json& j) { j["nodes"][0].erase("trigger"); }, "field 'approaches[2].kind'");
  // The controller's phase: 0 < φ < h, a timer at h.
  kOs.expect_refused([](nlohmann::json& j) { j["nodes"][1]["clock_offset_us"] = 0; }, "field 'nodes[1].clock_offset_us'");
  kOs.expect_refused([](nlohmann::json& j) { j["nodes"][1]["clock_offset_us"] = 50000; }, "field 'nodes[1].clock_offset_us'");
  kOs.expect_refused([](nlohmann::json& j) { j["nodes"][1]["period_us"] = 25000; }, "field 'nodes[1].period_us'");
  kOs.expect_refused(
      [](nlohmann::json& j) {
        j["nodes"][1]["mode"] = "arrival";
        j["nodes"][1].erase("period_us");
      },
      "field 'nodes[1].mode'");
  kOs.expect_refused([](nlohmann::json& j) { j["nodes"][0]["clock_offset_us"] = 100; }, "field 'nodes[0].clock_offset_us'");
  // No analytic cost for the one-shot loops.
  const NcsStudy s = kOs.study([](nlohmann::json&) {}, 3);
  try {
    static_cast<void>(run_ncs_sweep(s, 2, 1, engine::Shard{}, true));
    ADD_FAILURE() << "--analytic accepted";
  } catch (const engine::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("field '--analytic'"), std::string::npos) << e.what();
  }
}

/// The sensor under MTM {σ, δ, k_max, k_ref_max}, no loss on sc.
std::function<void(nlohmann::json&)> lossless_mtm(double sigma, double delta, int k_max, int k_ref_max) {
  return [=](nlohmann::json& j) {
    j["nodes"][0]["trigger"] = {{"rule", "mtm"}, {"sigma", sigma}, {"delta", delta}, {"k_max", k_max}, {"k_ref_max", k_ref_max}};
    j["links"][0].erase("loss");
  };
}

TEST(StudyOneShotMtm, AtZeroThresholdsAndKMaxOneItIsPeriodicSending) {
  // σ = 0, δ = 0, k_max = 1: every sample is sent, so OS and OSp under MTM are OSK bit for bit
  // (OS's held value never serves: a sample arrives for every period the chain fits in).
  const NcsStudy s = kOs.study(lossless_mtm(0, 0, 1, 0), 4);
  for (std::size_t x = 0; x < s.scenarios.size(); ++x) {
    for (std::uint64_t seed = 1; seed <= 3; ++seed) {
      const ncs::RunResult osk = ncs::run(*s.ctx, ncs::Approach::kOSK, s.scenarios[x], seed, ncs::RunOptions{});
      for (const ncs::Approach a : {ncs::Approach::kOS, ncs::Approach::kOSp}) {
        const ncs::RunResult r = ncs::run(*s.ctx, a, s.scenarios[x], seed, ncs::RunOptions{});
        EXPECT_EQ(r.sent, r.sampled) << ncs::name(a);
        EXPECT_EQ(r.cost, osk.cost) << ncs::name(a) << " " << x << " " << seed;
        EXPECT_EQ(r.nees, osk.nees) << ncs::name(a);
        EXPECT_EQ(r.late, osk.late) << ncs::name(a);
      }
    }
  }
}

TEST(StudyOneShotMtm, ASilentSensorSendsItsFirstSampleAndOnePerSetPointChange) {
  // δ far above any move, no safety rule: the sensor sends its first sample and, k_ref,max samples
  // after each set-point change, one more. 4 s: the square waves switch at 1, 2, 3 s (T_r 2 s) and
  // at 2 s (T_r 4 s); with k_ref,max = 3 the send 0.15 s after the change at 3 s is still in the run.
  const NcsStudy s = kOs.study(lossless_mtm(0, 1e6, 0, 3), 4);
  const std::uint32_t changes[] = {3, 1};
  const double h_s = s.ctx->period_us() * 1e-6;
  ncs::RunOptions record;
  record.record_messages = true;
  for (std::size_t x = 0; x < s.scenarios.size(); ++x) {
    // When: the first sample at 0, then k_ref,max = 3 periods after each switch (T_r/2, T_r, ...).
    std::vector<double> expected_s = {0};
    const double half_s = s.scenarios[x].period_s / 2;
    for (int i = 1; i * half_s < 4; ++i) expected_s.push_back(i * half_s + 3 * h_s);
    for (const ncs::Approach a : {ncs::Approach::kOS, ncs::Approach::kOSp}) {
      const ncs::RunResult r = ncs::run(*s.ctx, a, s.scenarios[x], 1, record);
      EXPECT_EQ(r.sent, 1 + changes[x]) << ncs::name(a) << " " << x;
      EXPECT_EQ(r.sampled, 80U);
      std::vector<double> sent_s;
      for (const ncs::MessageEvent& m : r.messages)
        if (m.leg == "sc") sent_s.push_back(m.sent_s);
      ASSERT_EQ(sent_s.size(), expected_s.size()) << ncs::name(a) << " " << x;
      for (std::size_t i = 0; i < sent_s.size(); ++i) EXPECT_NEAR(sent_s[i], expected_s[i], 1e-9) << ncs::name(a) << " " << i;
    }
  }
  // A relative term σ > 0 widens the threshold (σ y² + δ): fewer sends than δ alone; OS cannot
  // run with it (its held value's bound depends on y), OSp and OSK can.
  const auto sent = [](const NcsStudy& st) {
    std::uint32_t n = 0;
    for (const ncs::Scenario& x : st.scenarios) n += ncs::run(*st.ctx, ncs::Approach::kOSp, x, 2, ncs::RunOptions{}).sent;
    return n;
  };
  const auto osp_only = [](double sigma) {
    return [sigma](nlohmann::json& j) {
      lossless_mtm(sigma, 1e-4, 10, 0)(j);
      j["approaches"] = nlohmann::json::parse(R"([{"name": "I", "kind": "I"}, {"name": "OSp", "kind": "OSp"}])");
    };
  };
  EXPECT_LT(sent(kOs.study(osp_only(0.5), 4)), sent(kOs.study(osp_only(0), 4)));
  kOs.expect_refused(lossless_mtm(0.1, 1e-4, 10, 0), "field 'nodes[0].trigger.sigma'");
  kOs.expect_refused(
      [](nlohmann::json& j) {
        lossless_mtm(0, 1e-4, 10, 0)(j);
        j["approaches"] = nlohmann::json::parse(R"([{"name": "I", "kind": "I"}, {"name": "IK", "kind": "IK"}])");
      },
      "field 'nodes[0].trigger'");
  // The same bytes on 1 and 2 threads, the rule in the sweep's configuration.
  const NcsStudy m = kOs.study(lossless_mtm(0, 4e-4, 10, 2), 3);
  const std::string one = run_outputs(run_ncs_sweep(m, 3, 1, engine::Shard{}), temp_dir("mtm_one"), false).dump();
  const std::string two = run_outputs(run_ncs_sweep(m, 3, 2, engine::Shard{}), temp_dir("mtm_two"), false).dump();
  EXPECT_EQ(one, two);
  EXPECT_EQ(run_ncs_sweep(m, 2, 1, engine::Shard{}).spec.config.at("one_shot").at("mtm").at("k_ref_max"), 2);
}

// ---- The one-shot controller's job on a CPU (examples/ncs_cpu_one_shot.json): its timer at
// kh + φ releases the job, the command leaves at its finish.

TEST(StudyCpuOneShot, EveryControllerResponseIsWithinTheAnalysedBounds) {
  for (const char* scheduler : {"fixed_priority", "fixed_priority_nonpreemptive", "edf"}) {
    const NcsStudy s = kOsCpu.study([&](nlohmann::json& j) { j["cpus"][0]["scheduler"] = scheduler; }, 2);
    const nlohmann::json j = run_outputs(run_ncs_sweep(s, 20, 2, engine::Shard{}), oneshot_temp_dir(scheduler), false);
    const ncs::ControllerCpu& c = *s.scenarios[0].controller_cpu;
    EXPECT_GT(c.wcrt, c.bcrt);
    // One job per timer (20 seeds x 2 scenarios x 40 periods), nothing lost.
    test_support::expect_controller_jobs_within_bounds(j, c, {"OS", "OSp", "OSK"}, 20 * 2 * 40, scheduler);
  }
}

TEST(StudyCpuOneShot, ALoneConstantJobIsTheLoopWithThatConstantTauC) {
  test_support::expect_lone_constant_job_is_the_constant_delay(kOsCpu);
}

TEST(StudyCpuOneShot, CheckAnalysesTheTimerJobAsPeriodicAtItsPhase) {
  nlohmann::json j = kOsCpu.json();
  // One background task (T 10 ms, C 2 ms) above the job (C 3 ms): WCRT 5 ms, BCRT 3 ms.
  j["cpus"][0]["context_switch_us"] = 0;
  j["cpus"][0].erase("isrs");
  j["cpus"][0]["tasks"] = {{{"name", "bg"}, {"period_us", 10000}, {"wcet_us", 2000}, {"priority", 1}}};
  j["nodes"][1]["job"] = {{"wcet_us", 3000}, {"priority", 2}};
  const nlohmann::json r =
      resolve_study(engine::parse_study(j.dump(), kOsCpu.path(), &ncs_schema(), ONESHOT_STUDY_EXAMPLES_DIR));
  const nlohmann::json& job = r.at("cpus")[0].at("tasks")[1];
  EXPECT_EQ(job.at("node"), "controller");
  EXPECT_EQ(job.at("kind"), "node job (timer)");
  EXPECT_EQ(job.at("period_us").get<double>(), 50000);  // h, not h − J: its own timer
  EXPECT_EQ(job.at("deadline_us").get<double>(), 50000);
  EXPECT_EQ(job.at("wcrt_us").get<double>(), 5000);
  EXPECT_EQ(job.at("bcrt_us").get<double>(), 3000);
}

TEST(StudyCpuOneShot, SameBytesOnOneAndTwoThreadsAndBadJobsRefused) {
  const NcsStudy s = kOsCpu.study([](nlohmann::json&) {}, 1.5);
  const std::string one = run_outputs(run_ncs_sweep(s, 3, 1, engine::Shard{}), oneshot_temp_dir("os_one"), false).dump();
  const std::string two = run_outputs(run_ncs_sweep(s, 3, 2, engine::Shard{}), oneshot_temp_dir("os_two"), false).dump();
  EXPECT_EQ(one, two);
  EXPECT_TRUE(nlohmann::json::parse(two).contains("cpu"));
  const auto refused = [](const std::function<void(nlohmann::json&)>& edit, const std::string& expect) {
    try {
      static_cast<void>(kOsCpu.study(edit, 1));
      ADD_FAILURE() << "accepted, expected " << expect;
    } catch (const engine::InputError& e) {
      EXPECT_NE(std::string(e.what()).find(expect), std::string::npos) << e.what();
    }
  };
  refused([](nlohmann::json& j) { j["nodes"][1]["job"] = {{"wcet_us", 60000}, {"priority", 3}}; }, "field 'nodes[1].job.wcet_us'");  // > h
  refused([](nlohmann::json& j) { j["nodes"][1]["job"]["deadline_us"] = 1500; }, "field 'nodes[1].job'");  // it misses
  refused([](nlohmann::json& j) { j["nodes"][1].erase("job"); }, "field 'nodes[1].job'");
  refused([](nlohmann::json& j) { j["nodes"][0]["cpu"] = "dspic"; j["nodes"][0]["job"] = {{"wcet_us", 100}, {"priority", 5}}; },
          "field 'nodes[0].cpu'");  // the sensor runs on its timer
}

}  // namespace
}  // namespace oneshot::study
