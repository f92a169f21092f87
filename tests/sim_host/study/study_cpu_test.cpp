/// @file study_cpu_test.cpp
/// @brief The controller's job on a modeled CPU (sim_host/study/examples/ncs_cpu.json, a
///        study file's `cpus`): every observed τ_c within the analysis's [BCRT, WCRT], a lone
///        constant job equal to the loop with that constant τ_c, the check's analysis against
///        hand-computed response times, a heavier background raising the mean τ_c and the
///        cost, the same bytes on 1 and 2 threads and from merged shards, and bad `cpus`
///        input refused naming the field; the sensor's sampling job: every sample's lag
///        behind kh within the analysed sampling latencies, a lone constant job equal to the
///        loop with sc later by its C, refusals (examples/ncs_cpu_sensor.json).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>

#include "ncs_cpu.hpp"
#include "ncs_loop.hpp"
#include "oneshot/engine/study_file.hpp"
#include "study_check.hpp"
#include "study_ncs_runner.hpp"
#include "study_ncs_sweep.hpp"
#include "support/run_command.hpp"
#include "study_cpu_checks.hpp"
#include "study_example.hpp"
#include "study_sweep_checks.hpp"
#include "support/temp_files.hpp"

namespace oneshot::study {
namespace {

const test_support::StudyExample kCpu("ncs_cpu.json");
const test_support::StudyExample kSensorCpu("ncs_cpu_sensor.json");

std::string cpu_temp_dir(const char* name) { return test::fresh_dir("oneshot_study_cpu_test", name); }

/// Keeps the approaches named in `keep` (I first).
void only(nlohmann::json& j, std::initializer_list<const char*> keep) {
  nlohmann::json a = nlohmann::json::array();
  for (const char* k : keep) a.push_back({{"name", k}, {"kind", k}});
  j["approaches"] = a;
}

TEST(StudyCpu, EveryControllerResponseIsWithinTheAnalysedBounds) {
  for (const char* scheduler : {"fixed_priority", "fixed_priority_nonpreemptive", "edf"}) {
    const NcsStudy s = kCpu.study(
        [&](nlohmann::json& j) {
          j["cpus"][0]["scheduler"] = scheduler;
          only(j, {"I", "S", "A", "AKl"});
        },
        2);
    const nlohmann::json j = run_outputs(run_ncs_sweep(s, 30, 2, engine::Shard{}), cpu_temp_dir(scheduler), false);
    // One job per period (30 seeds x 2 scenarios x 40 periods), nothing lost.
    test_support::expect_controller_jobs_within_bounds(j, *s.scenarios[0].controller_cpu, {"S", "A", "AKl"}, 30 * 2 * 40,
                                                       scheduler);
  }
}

TEST(StudyCpu, ALoneConstantJobIsTheLoopWithThatConstantTauC) {
  test_support::expect_lone_constant_job_is_the_constant_delay(kCpu);
}

TEST(StudyCpu, CheckGivesTheHandComputedResponseTimes) {
  nlohmann::json j = kCpu.json();
  // One background task (T 10 ms, C 2 ms) above the job (C 3 ms constant), no switches or ISRs:
  // WCRT = 3 + 2 = 5 ms (one preemption), BCRT = 3 ms (Redell-Sanfridson: ceil((3 - 10)/10) = 0).
  j["cpus"][0]["context_switch_us"] = 0;
  j["cpus"][0].erase("isrs");
  j["cpus"][0]["tasks"] = {{{"name", "bg"}, {"period_us", 10000}, {"wcet_us", 2000}, {"priority", 1}}};
  j["nodes"][1]["job"] = {{"wcet_us", 3000}, {"priority", 2}};
  const nlohmann::json r = resolve_study(kCpu.parse(j));
  const nlohmann::json& c = r.at("cpus")[0];
  EXPECT_TRUE(c.at("schedulable").get<bool>());
  // Inputs: h = 50 ms, the actuation-synchronized approaches chain as and sc (U[0.5, 4] ms each):
  // J = 3.5 + 3.5 ms, minimum inter-arrival h - J = 43 ms, deadline h.
  EXPECT_EQ(c.at("input_jitter_us").get<double>(), 7000);
  const nlohmann::json& job = c.at("tasks")[1];
  EXPECT_EQ(job.at("node"), "controller");
  EXPECT_EQ(job.at("period_us").get<double>(), 43000);
  EXPECT_EQ(job.at("deadline_us").get<double>(), 50000);
  EXPECT_EQ(job.at("wcrt_us").get<double>(), 5000);
  EXPECT_EQ(job.at("bcrt_us").get<double>(), 3000);
  EXPECT_EQ(c.at("tasks")[0].at("wcrt_us").get<double>(), 2000);
  // Sampling approaches only: J = the spread of sc alone.
  only(j, {"I", "S", "SK"});
  EXPECT_EQ(resolve_study(kCpu.parse(j)).at("cpus")[0].at("input_jitter_us").get<double>(), 3500);
  // AKl's D = max sc + max ca + WCRT.
  nlohmann::json k = kCpu.json();
  k["cpus"][0] = j["cpus"][0];
  k["nodes"][1]["job"] = j["nodes"][1]["job"];
  const NcsStudy s = map_ncs_study(kCpu.parse(k));
  EXPECT_EQ(s.ctx->worst_chain_us(s.scenarios[0]), 4000 + 4000 + 5000);
}

/// Mean τ_c and the paired cost of `approach` with the background tasks' periods × `scale`.
std::pair<double, double> load_point(double scale, const char* approach) {
  const NcsStudy s = kCpu.study(
      [&](nlohmann::json& j) {
        for (auto& t : j["cpus"][0]["tasks"]) t["period_us"] = std::llround(t["period_us"].get<double>() * scale);
        only(j, {"I", approach});
      },
      4);
  const nlohmann::json j = run_outputs(run_ncs_sweep(s, 20, 2, engine::Shard{}), cpu_temp_dir("load"), false);
  const double mean = j.at("cpu").at(approach).at("mean_us").get<double>();
  const double cost = j.at("approaches").at(approach).at("cost_mean").get<double>();
  std::printf("background periods x %.2f: %s mean tau_c %.1f us (WCRT %.1f), J %.6f\n", scale, approach, mean,
              j.at("cpu").at(approach).at("wcrt_us").get<double>(), cost);
  return {mean, cost};
}

TEST(StudyCpu, AHeavierBackgroundRaisesTheMeanResponseAndTheCost) {
  // S applies on arrival: a longer tau_c delays every command and costs more (same seeds: the
  // noise and the delays are common to the three loads).
  const auto s_light = load_point(4, "S");
  const auto s_file = load_point(1, "S");
  const auto s_heavy = load_point(0.75, "S");
  EXPECT_LT(s_light.first, s_file.first);
  EXPECT_LT(s_file.first, s_heavy.first);
  EXPECT_LT(s_light.second, s_file.second);
  EXPECT_LT(s_file.second, s_heavy.second);
  // A applies at the next period boundary: while no command is late its cost does not depend
  // on tau_c at all.
  const auto a_light = load_point(4, "A");
  const auto a_heavy = load_point(0.75, "A");
  EXPECT_LT(a_light.first, a_heavy.first);
  EXPECT_NEAR(a_light.second, a_heavy.second, 1e-12 * a_light.second);
}

TEST(StudyCpu, SameBytesOnOneAndTwoThreadsAndFromMergedShards) {
  test_support::expect_same_bytes_on_threads_and_shards(kCpu.study([](nlohmann::json&) {}, 1.5), 3,
                                                        "oneshot_study_cpu_test", "cpu");
}

/// Parsing, checking and mapping the edited file is refused, the message containing `expect`.
void expect_cpu_refused(const test_support::Edit& edit, const std::string& expect) { kCpu.expect_refused(edit, expect, true); }

TEST(StudyCpu, BadCpusAreRefusedNamingTheField) {
  expect_cpu_refused([](nlohmann::json& j) { j["nodes"][1]["cpu"] = "arm"; }, "field 'nodes[1].cpu'");  // dangling
  expect_cpu_refused([](nlohmann::json& j) { j["cpus"][0]["tasks"][0]["wcet_us"] = 6000; }, "field 'cpus[0].tasks[0].wcet_us'");  // > period
  expect_cpu_refused([](nlohmann::json& j) { j["cpus"][0]["tasks"][0]["bcet_us"] = 700; }, "field 'cpus[0].tasks[0].bcet_us'");
  expect_cpu_refused([](nlohmann::json& j) { j["cpus"][0]["tasks"][1]["name"] = "comm"; }, "field 'cpus[0].tasks[1].name'");  // duplicate
  expect_cpu_refused([](nlohmann::json& j) { j["cpus"].push_back(j["cpus"][0]); }, "field 'cpus[1].name'");  // duplicate CPU
  expect_cpu_refused([](nlohmann::json& j) { j["cpus"][0]["tasks"][0]["name"] = "controller"; }, "field 'nodes[1].name'");
  expect_cpu_refused([](nlohmann::json& j) { j["cpus"][0]["scheduler"] = "round_robin"; }, "field 'cpus[0].scheduler'");
  expect_cpu_refused([](nlohmann::json& j) { j["cpus"][0]["tasks"][2]["wcet_us"] = 12000; }, "field 'cpus[0].tasks[2]'");  // unschedulable
  expect_cpu_refused([](nlohmann::json& j) { j["nodes"][1]["job"]["deadline_us"] = 3500; }, "field 'nodes[1].job'");  // it misses
  expect_cpu_refused([](nlohmann::json& j) { j["nodes"][1].erase("job"); }, "field 'nodes[1].job'");
  expect_cpu_refused([](nlohmann::json& j) { j["nodes"][1].erase("cpu"); }, "field 'nodes[1].job'");
  expect_cpu_refused([](nlohmann::json& j) { j["nodes"][1]["job"]["period_us"] = 50000; }, "field 'nodes[1].job.period_us'");
  expect_cpu_refused([](nlohmann::json& j) { j["nodes"][1]["job"]["sample_at"] = "end"; }, "field 'nodes[1].job.sample_at'");
  expect_cpu_refused([](nlohmann::json& j) { j["nodes"][1]["job"] = {{"wcet_us", 45000}, {"priority", 3}}; }, "field 'nodes[1].job.wcet_us'");  // > h - J
  expect_cpu_refused([](nlohmann::json& j) { j["nodes"][1]["job"]["exec"]["instructions_max"] = 2'000'000; }, "field 'nodes[1].job.exec'");
  expect_cpu_refused([](nlohmann::json& j) { j["nodes"][0]["cpu"] = "dspic"; j["nodes"][0]["job"] = {{"wcet_us", 100}, {"priority", 5}}; },
                 "field 'nodes[0].cpu'");  // the sensor runs on its timer
  expect_cpu_refused([](nlohmann::json& j) { j["cpus"].push_back({{"name", "spare"}, {"scheduler", "edf"}}); }, "field 'cpus[1]'");
  expect_cpu_refused([](nlohmann::json& j) { j["approaches"].push_back({{"name", "S+"}, {"kind", "S+"}}); }, "field 'approaches[7].kind'");
  expect_cpu_refused([](nlohmann::json& j) { j["links"][1]["delay"] = {{"model", "poisson_periods"}, {"mean_periods", 1}, {"period_us", 1000}}; },
                 "field 'nodes[1].cpu'");  // no bound on the input's arrival
}

TEST(StudyCpu, CommandLine) {
  // check prints every task's analysis, the node job's as the JSON gives it.
  const test::CommandResult ok = test::run_command({ONESHOT_SIM_PATH, "study", "check", kCpu.path()});
  ASSERT_EQ(ok.exit_code, 0) << ok.output;
  const nlohmann::json r = resolve_study(kCpu.parse(kCpu.json()));
  const nlohmann::json& c = r.at("cpus")[0];
  EXPECT_NE(ok.output.find("cpu dspic: fixed_priority"), std::string::npos) << ok.output;
  for (const nlohmann::json& t : c.at("tasks")) {
    const std::string line = t.at("name").get<std::string>() + " (T " + t.at("period_us").dump();
    EXPECT_NE(ok.output.find(line), std::string::npos) << line << "\n" << ok.output;
    const std::string bounds = "WCRT " + t.at("wcrt_us").dump() + " us, BCRT " + t.at("bcrt_us").dump() + " us";
    EXPECT_NE(ok.output.find(bounds), std::string::npos) << bounds << "\n" << ok.output;
  }
  EXPECT_NE(ok.output.find("node job (on input arrival) controller"), std::string::npos) << ok.output;
  // Its JSON: AKl's D = max sc + max ca + the controller job's WCRT (legs U[0.5, 4] ms).
  const std::string cj = test::made_dir("oneshot_study_cpu_test", "cli_json") + "/check.json";
  ASSERT_EQ(test::run_command({ONESHOT_SIM_PATH, "study", "check", kCpu.path(), "--json", cj}).exit_code, 0);
  const nlohmann::json cr = nlohmann::json::parse(test::read_file(cj));
  EXPECT_EQ(cr.at("cpus")[0], c);
  for (const nlohmann::json& a : cr.at("approaches")) {
    if (a.at("kind") != "AKl") continue;
    for (const auto& [sc, d] : a.at("per_scenario").items()) {
      EXPECT_EQ(d.at("late_sampling_d_us").get<double>(), 4000 + 4000 + std::ceil(c.at("tasks")[3].at("wcrt_us").get<double>())) << sc;
    }
  }
  // report: the CPU section with study run's figures.
  const std::string rep = test::fresh_dir("oneshot_study_cpu_test", "cli_report");
  const test::CommandResult rp = test::run_command(
      {ONESHOT_SIM_PATH, "study", "report", kCpu.path(), rep, "--seeds", "2", "--max-duration", "2.5", "--no-plots", "--threads", "1"});
  ASSERT_EQ(rp.exit_code, 0) << rp.output;
  const std::string md = test::read_file(rep + "/report.md");
  const nlohmann::json rj = nlohmann::json::parse(test::read_file(rep + "/report.json"));
  EXPECT_NE(md.find("### Controller CPU"), std::string::npos);
  char row[128];
  const nlohmann::json& s_cpu = rj.at("cpu").at("S");
  std::snprintf(row, sizeof row, "| S | %.0f | %.1f | %.1f | %.1f |", s_cpu.at("jobs").get<double>(), s_cpu.at("min_us").get<double>(),
                s_cpu.at("mean_us").get<double>(), s_cpu.at("max_us").get<double>());
  EXPECT_NE(md.find(row), std::string::npos) << row << "\n" << md;
  // An unschedulable CPU: check and run refuse it in one line naming the task, nothing written.
  nlohmann::json bad = kCpu.json();
  bad["plant"]["file"] = std::string(ONESHOT_STUDY_EXAMPLES_DIR) + "/../../../lut_gen/plants/networked_board.json";
  bad["cpus"][0]["tasks"][2]["wcet_us"] = 12000;
  const std::string dir = test::made_dir("oneshot_study_cpu_test", "cli_bad");
  std::ofstream(dir + "/study.json") << bad.dump();
  const std::string json = dir + "/check.json";
  std::filesystem::remove(json);
  const test::CommandResult ck = test::run_command({ONESHOT_SIM_PATH, "study", "check", dir + "/study.json", "--json", json});
  EXPECT_NE(ck.exit_code, 0);
  EXPECT_NE(ck.output.find("field 'cpus[0].tasks[2]': cpu 'dspic' is unschedulable"), std::string::npos) << ck.output;
  EXPECT_EQ(std::count(ck.output.begin(), ck.output.end(), '\n'), 1) << ck.output;
  EXPECT_FALSE(std::filesystem::exists(json));
  const std::string out = test::fresh_dir("oneshot_study_cpu_test", "cli_bad_run");
  const test::CommandResult rn = test::run_command({ONESHOT_SIM_PATH, "study", "run", dir + "/study.json", "--out", out});
  EXPECT_NE(rn.exit_code, 0);
  EXPECT_NE(rn.output.find("field 'cpus[0].tasks[2]'"), std::string::npos) << rn.output;
  EXPECT_FALSE(std::filesystem::exists(out));
}

// ---- The sensor's sampling job on a CPU (examples/ncs_cpu_sensor.json): released by its timer
// at kh, it samples at its start and sends at its finish.

/// The file `j` mapped onto the loop, every scenario `duration_s` long.
NcsStudy sensor_study(const nlohmann::json& j, double duration_s) {
  return kSensorCpu.study([&j](nlohmann::json& x) { x = j; }, duration_s);
}

TEST(StudyCpuSensor, EverySampleLagsKhWithinTheAnalysedBounds) {
  for (const char* scheduler : {"fixed_priority", "fixed_priority_nonpreemptive", "edf"}) {
    nlohmann::json j = kSensorCpu.json();
    j["cpus"][0]["scheduler"] = scheduler;
    const NcsStudy s = sensor_study(j, 2);
    const ncs::ControllerCpu& c = *s.scenarios[0].sensor_cpu;
    ASSERT_LT(c.sample_min, c.sample_max);
    // study check gives the same lag bounds (the sensor job's "sample_lag_us").
    const nlohmann::json chk =
        resolve_study(kSensorCpu.parse(j));
    const nlohmann::json& bounds = chk.at("cpus")[0].at("tasks")[3].at("sample_lag_us");
    EXPECT_EQ(bounds[0].get<double>(), static_cast<double>(c.sample_min.count()) * 1e-3);
    EXPECT_EQ(bounds[1].get<double>(), static_cast<double>(c.sample_max.count()) * 1e-3);
    const double h_s = static_cast<double>(s.ctx->period_us()) * 1e-6;
    double lo = 1e9, hi = -1e9;
    std::size_t n = 0;
    for (ncs::Approach a : {ncs::Approach::kS, ncs::Approach::kSK}) {
      for (const ncs::Scenario& sc : s.scenarios) {
        for (std::uint64_t seed = 1; seed <= 20; ++seed) {
          const ncs::RunResult r = ncs::run(*s.ctx, a, sc, seed, ncs::RunOptions{});
          ASSERT_TRUE(r.sensor_cpu.present);
          EXPECT_EQ(r.sensor_cpu.jobs, 40U);
          EXPECT_EQ(r.sensor_cpu.deadline_misses, 0U);
          EXPECT_GE(r.sensor_cpu.response_min, c.bcrt);
          EXPECT_LE(r.sensor_cpu.response_max, c.wcrt);
          ASSERT_EQ(r.samples.size(), 40U);
          for (std::size_t k = 0; k < r.samples.size(); ++k) {  // the observed instants: lag behind kh
            const double lag = r.samples[k].t_s - static_cast<double>(k) * h_s;
            lo = std::min(lo, lag);
            hi = std::max(hi, lag);
            ++n;
          }
          EXPECT_GE(r.sensor_cpu.sample_min, c.sample_min);
          EXPECT_LE(r.sensor_cpu.sample_max, c.sample_max);
        }
      }
    }
    const double ns = 1e-9;
    EXPECT_GE(lo, static_cast<double>(c.sample_min.count()) * ns - 1e-12) << scheduler;
    EXPECT_LE(hi, static_cast<double>(c.sample_max.count()) * ns + 1e-12) << scheduler;
    EXPECT_GT(hi - lo, 1e-4) << scheduler;  // a real sampling jitter (the background preempts)
    std::printf("%s: %zu samples lag kh by %.1f .. %.1f us within [%.1f, %.1f]\n", scheduler, n, lo * 1e6, hi * 1e6,
                static_cast<double>(c.sample_min.count()) * 1e-3, static_cast<double>(c.sample_max.count()) * 1e-3);
  }
}

TEST(StudyCpuSensor, ALoneConstantJobIsTheLoopWithItsFrameLaterByC) {
  nlohmann::json j = kSensorCpu.json();
  j["cpus"][0].erase("tasks");
  j["cpus"][0].erase("isrs");
  j["cpus"][0]["context_switch_us"] = 0;
  j["nodes"][0]["job"] = {{"wcet_us", 345}, {"bcet_us", 345}, {"priority", 1}};
  const NcsStudy on_cpu = sensor_study(j, 3);
  // The oracle: no CPU, the sensor sampling at kh and sc's delay 345 us longer (the same draws).
  nlohmann::json k = j;
  k.erase("cpus");
  k["nodes"][0].erase("cpu");
  k["nodes"][0].erase("job");
  for (nlohmann::json& l : k["links"]) {
    if (l["name"] != "sc") continue;
    l["delay"]["min_us"] = l["delay"]["min_us"].get<int>() + 345;
    l["delay"]["max_us"] = l["delay"]["max_us"].get<int>() + 345;
  }
  const NcsStudy shifted = sensor_study(k, 3);
  EXPECT_EQ(on_cpu.scenarios[0].sensor_cpu->sample_min, engine::Duration{0});
  EXPECT_EQ(on_cpu.scenarios[0].sensor_cpu->sample_max, engine::Duration{0});
  for (ncs::Approach a : on_cpu.approaches) {
    for (std::size_t s = 0; s < on_cpu.scenarios.size(); ++s) {
      for (std::uint64_t seed = 1; seed <= 3; ++seed) {
        const ncs::RunResult x = ncs::run(*on_cpu.ctx, a, on_cpu.scenarios[s], seed, ncs::RunOptions{});
        const ncs::RunResult y = ncs::run(*shifted.ctx, a, shifted.scenarios[s], seed, ncs::RunOptions{});
        EXPECT_NEAR(x.cost, y.cost, 1e-12 * std::fabs(y.cost)) << ncs::name(a) << " seed " << seed;
        EXPECT_EQ(x.commands, y.commands);
        ASSERT_EQ(x.samples.size(), y.samples.size());
        for (std::size_t i = 0; i < x.samples.size(); ++i) EXPECT_EQ(x.samples[i].t_s, y.samples[i].t_s);
        if (x.sensor_cpu.present) {
          EXPECT_EQ(x.sensor_cpu.response_max, engine::from_us(345));
        }
      }
    }
  }
}

TEST(StudyCpuSensor, SameBytesOnOneAndTwoThreadsAndWhatTheLoopCannotRunIsRefused) {
  const NcsStudy s = sensor_study(kSensorCpu.json(), 1.5);
  const std::string one = run_outputs(run_ncs_sweep(s, 3, 1, engine::Shard{}), cpu_temp_dir("sensor_one"), false).dump();
  const std::string two = run_outputs(run_ncs_sweep(s, 3, 2, engine::Shard{}), cpu_temp_dir("sensor_two"), false).dump();
  EXPECT_EQ(one, two);
  try {
    static_cast<void>(run_ncs_sweep(s, 1, 1, engine::Shard{}, true));
    ADD_FAILURE() << "--analytic accepted";
  } catch (const engine::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("field '--analytic'"), std::string::npos) << e.what();
  }
  const auto refused = [](const test_support::Edit& edit, const std::string& expect) { kSensorCpu.expect_refused(edit, expect); };
  const nlohmann::json as = {{"name", "as"}, {"from", "actuator"}, {"to", "sensor"},
                             {"delay", {{"model", "uniform"}, {"min_us", 500}, {"max_us", 4000}, {"resolution_us", 1}}}};
  refused([&](nlohmann::json& j) { j["links"].push_back(as); j["approaches"].push_back({{"name", "A"}, {"kind", "A"}}); },
          "field 'approaches[4].kind'");  // actuation-synchronized: the sensor samples on the request
  refused([&](nlohmann::json& j) { j["links"].push_back(as); j["approaches"].push_back({{"name", "AKl"}, {"kind", "AKl"}}); },
          "field 'approaches[4].kind'");  // AKl's D assumes the exact instant t_k − D
  refused([](nlohmann::json& j) { j["approaches"].push_back({{"name", "S+"}, {"kind", "S+"}}); }, "field 'approaches[4].kind'");
  refused([](nlohmann::json& j) { j["nodes"][1]["cpu"] = "dspic"; j["nodes"][1]["job"] = {{"wcet_us", 1000}, {"priority", 5}}; },
          "field 'nodes[0].cpu'");  // sensor and controller together: not analysed
  refused([](nlohmann::json& j) { j["nodes"][2]["cpu"] = "dspic"; j["nodes"][2]["job"] = {{"wcet_us", 100}, {"priority", 5}}; },
          "field 'nodes[2].cpu'");  // the actuator's job: not modelled
  refused([](nlohmann::json& j) { j["nodes"][0]["job"] = {{"wcet_us", 60000}, {"priority", 3}}; }, "field 'nodes[0].job.wcet_us'");
  refused([](nlohmann::json& j) { j["nodes"][0]["job"]["deadline_us"] = 300; }, "field 'nodes[0].job'");  // it misses
}

}  // namespace
}  // namespace oneshot::study
