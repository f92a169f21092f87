/// @file study_petc_test.cpp
/// @brief "study": "petc" files (sim_host/study/study_petc_*.cpp): the shipped example against
///        `oneshot-sim petc table` on the same seeds, the same bytes on 1 and 2 threads and from
///        merged shards, the noise-free runs seed-independent with TTS on its deterministic
///        response, check's design, report, bench, and the refusals naming the field.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "oneshot/engine/study_file.hpp"
#include "oneshot/engine/sweep.hpp"
#include "oneshot/util/output_files.hpp"
#include "study_petc_study.hpp"
#include "support/run_command.hpp"
#include "support/temp_files.hpp"

namespace oneshot::study {
namespace {

const std::string kPetcExample = std::string(ONESHOT_STUDY_EXAMPLES_DIR) + "/petc.json";

nlohmann::json petc_example_json() { return nlohmann::json::parse(test::read_file(kPetcExample)); }

std::shared_ptr<const PetcStudy> petc_map_text(const nlohmann::json& j) {
  return map_petc_study(engine::parse_study(j.dump(), kPetcExample, &petc_schema(), ONESHOT_STUDY_EXAMPLES_DIR));
}

test::CommandResult petc_sim(std::vector<std::string> args) {
  args.insert(args.begin(), ONESHOT_SIM_PATH);
  return test::run_command(args);
}

TEST(StudyPetc, ExampleGivesTheMetricsOfPetcTable) {
  const std::string dir = test::made_dir("oneshot_study_petc", "oracle");
  const test::CommandResult a =
      petc_sim({"study", "run", kPetcExample, "--seeds", "3", "--threads", "2", "--out", dir + "/study", "--json", dir + "/study.json"});
  ASSERT_EQ(a.exit_code, 0) << a.output;
  const test::CommandResult b = petc_sim({"petc", "table", "--seeds", "3", "--threads", "2", "--no-plots", "--out", dir + "/petc",
                                          "--json", dir + "/petc.json"});
  ASSERT_EQ(b.exit_code, 0) << b.output;
  const nlohmann::json s = nlohmann::json::parse(test::read_file(dir + "/study.json"));
  const nlohmann::json t = nlohmann::json::parse(test::read_file(dir + "/petc.json"));
  ASSERT_EQ(s.at("approaches").size(), t.at("cases").size());
  // The same runs summed in the same order: measured 0 relative difference; 1e-12 allowed.
  std::size_t compared = 0;
  for (const nlohmann::json& c : t.at("cases")) {
    const nlohmann::json& mine = s.at("approaches").at(c.at("case").get<std::string>());
    for (const auto& [name, v] : c.at("metrics").items())
      for (const char* f : {"mean", "ci95"}) {
        const double x = mine.at("metrics").at(name).at(f).get<double>(), y = v.at(f).get<double>();
        EXPECT_LE(std::fabs(x - y), 1e-12 * std::fabs(y)) << c.at("case") << " " << name << " " << f << ": " << x << " vs " << y;
        ++compared;
      }
    // cost = GPI; per-link sent counters = the packets over the runs.
    EXPECT_EQ(mine.at("cost_mean").get<double>(), mine.at("metrics").at("GPI").at("mean").get<double>());
    const double sc = s.at("links").at(c.at("case").get<std::string>()).at("sc").at("sent").get<double>();
    EXPECT_NEAR(sc, 3 * c.at("metrics").at("sensor_packets").at("mean").get<double>(), 1e-9 * sc);
  }
  EXPECT_EQ(compared, 7U * 20U * 2U);
  EXPECT_EQ(s.at("approaches").at("1").at("ratio_to_1").get<double>(), 1.0);
  EXPECT_EQ(s.at("order_by_mean_cost").size(), 7U);
  EXPECT_EQ(s.at("paired_differences").size(), 21U);
}

TEST(StudyPetc, SameBytesOnOneAndTwoThreadsAndFromMergedShards) {
  const std::string dir = test::made_dir("oneshot_study_petc", "bytes");
  const auto run = [&](std::vector<std::string> extra) {
    std::vector<std::string> argv{"study", "run", kPetcExample, "--seeds", "4"};
    argv.insert(argv.end(), extra.begin(), extra.end());
    const test::CommandResult r = petc_sim(argv);
    EXPECT_EQ(r.exit_code, 0) << r.output;
  };
  run({"--threads", "1", "--out", dir + "/t1", "--json", dir + "/t1.json"});
  run({"--threads", "2", "--out", dir + "/t2", "--json", dir + "/t2.json"});
  run({"--shard", "0/2", "--out", dir + "/sh"});
  run({"--shard", "1/2", "--out", dir + "/sh"});
  const test::CommandResult m = petc_sim({"merge", dir + "/sh/run.shard-1-of-2.json", dir + "/sh/run.shard-0-of-2.json", "--out",
                                          dir + "/m", "--json", dir + "/m.json"});
  ASSERT_EQ(m.exit_code, 0) << m.output;
  const std::string one = test::read_file(dir + "/t1.json");
  ASSERT_FALSE(one.empty());
  EXPECT_EQ(one, test::read_file(dir + "/t2.json"));
  EXPECT_EQ(one, test::read_file(dir + "/m.json"));
  EXPECT_EQ(test::read_file(dir + "/t1/runs.csv"), test::read_file(dir + "/m/runs.csv"));
}

TEST(StudyPetc, NoiseFreeRunsAreSeedIndependentAndTtsIsItsDeterministicResponse) {
  nlohmann::json j = petc_example_json();
  j["scenarios"][0]["params"] = {{"noise", 0}};  // every approach noise-free, whatever its own params.noise
  const std::shared_ptr<const PetcStudy> s = petc_map_text(j);
  const engine::SweepResults r = run_petc_sweep(*s, 3, 2, engine::Shard{});
  for (std::size_t a = 0; a < r.spec.approaches.size(); ++a) {
    EXPECT_FALSE(s->runs[a][0].noise) << r.spec.approaches[a];
    for (std::size_t m = 0; m < r.spec.metrics.size(); ++m)
      for (std::size_t k = 1; k < r.spec.seeds; ++k)
        EXPECT_EQ(r.at(a, 0, k, m), r.at(a, 0, 0, m)) << r.spec.approaches[a] << " " << r.spec.metrics[m] << " seed " << k;
  }
  // TTS (approach 1): its output is the setup's deterministic y^TTS, so ISEP = 0 and N_E = 0
  // exactly; both nodes send every period (U_c = U_a = 1), GPI = 0.9; ISE = sqrt(sum (r - y^TTS)^2).
  const sim::petc::PetcSetup& st = s->setups[0];
  double ise2 = 0;
  for (double y : st.y_tts) ise2 += (1.0 - y) * (1.0 - y);
  EXPECT_EQ(st.y_tts.size(), 464U);
  EXPECT_EQ(r.at(0, 0, 0, r.metric("ISEP")), 0.0);
  EXPECT_EQ(r.at(0, 0, 0, r.metric("N_E")), 0.0);
  EXPECT_EQ(r.at(0, 0, 0, r.metric("U_c")), 1.0);
  EXPECT_EQ(r.at(0, 0, 0, r.metric("U_a")), 1.0);
  EXPECT_NEAR(r.at(0, 0, 0, r.metric("cost")), 0.9, 1e-15);
  EXPECT_EQ(r.at(0, 0, 0, r.metric("ISE")), std::sqrt(ise2));
  // The noise-free scenario's case 4 is case 3 (the same settings once the noise is off).
  for (std::size_t m = 0; m < r.spec.metrics.size(); ++m) EXPECT_EQ(r.at(3, 0, 0, m), r.at(2, 0, 0, m)) << r.spec.metrics[m];
}

TEST(StudyPetc, ScenarioOverridesReachTheDesign) {
  nlohmann::json j = petc_example_json();
  // A step of 2 without noise: the TTS loop is linear from rest, so r - y doubles and its ISE
  // with it (measured 0 relative difference: doubling is exact in binary; 1e-14 allowed).
  j["scenarios"].push_back({{"name", "step2"}, {"params", {{"noise", 0}, {"sigma_w", 1e-4}, {"sigma_v", 2e-4}}},
                            {"reference", {{"kind", "steps"}, {"steps", {{0, 2}}}}}});
  j["scenarios"].push_back({{"name", "short"}, {"duration_s", 0.002}, {"params", {{"ratio", 1}, {"dob_cutoff_hz", 500}}}});
  const std::shared_ptr<const PetcStudy> s = petc_map_text(j);
  ASSERT_EQ(s->setups.size(), 3U);
  EXPECT_NEAR(s->setups[1].ise, 2 * s->setups[0].ise, 1e-14 * s->setups[0].ise);
  EXPECT_EQ(s->setups[1].opt.reference, 2.0);
  EXPECT_NEAR(std::sqrt(s->setups[1].plant.augmented.w), 1e-4, 1e-18);
  EXPECT_NEAR(std::sqrt(s->setups[1].plant.augmented.v), 2e-4, 1e-18);
  EXPECT_EQ(s->setups[2].opt.steps, 100U);
  EXPECT_EQ(s->setups[2].mrci.ratio, 1U);
  EXPECT_EQ(s->setups[2].dob.cutoff_hz, 500.0);
  for (std::size_t a = 0; a < s->approaches.size(); ++a) {
    EXPECT_FALSE(s->runs[a][1].noise);
    EXPECT_EQ(s->runs[a][2].noise, s->runs[a][0].noise);
  }
  const engine::SweepResults r = run_petc_sweep(*s, 2, 2, engine::Shard{});
  EXPECT_EQ(r.at(0, 1, 0, r.metric("ISEP")), 0.0);  // TTS on its own y^TTS at r = 2
  EXPECT_EQ(r.at(0, 2, 0, r.metric("sensor_packets")), 100.0);
}

TEST(StudyPetc, CheckGivesTheDesignReportAndBenchRun) {
  const std::string dir = test::made_dir("oneshot_study_petc", "check");
  test::CommandOptions to_file;
  to_file.stdout_path = dir + "/check.json";
  const test::CommandResult c = test::run_command({ONESHOT_SIM_PATH, "study", "check", kPetcExample, "--json", "-"}, to_file);
  ASSERT_EQ(c.exit_code, 0) << c.output;
  const nlohmann::json r = nlohmann::json::parse(test::read_file(dir + "/check.json"));
  EXPECT_EQ(r.at("runs_with"), "petc");
  const nlohmann::json& d = r.at("petc");
  EXPECT_EQ(d.at("approaches").size(), 7U);
  const nlohmann::json& mrci = d.at("scenarios")[0].at("design").at("mrci");
  EXPECT_EQ(mrci.at("slow_modes").size(), 2U);
  EXPECT_EQ(d.at("scenarios")[0].at("config").at("steps"), 464);
  EXPECT_EQ(d.at("approaches")[4].at("per_scenario")[0].at("sigma_s").get<double>(), 1e-7);
  EXPECT_EQ(d.at("approaches")[3].at("per_scenario")[0].at("sigma_c").get<double>(), 1.32e-2);  // the node's trigger

  // report (no plots) holds study run's table verbatim; the traced runs are the sweep's.
  const test::CommandResult rep =
      petc_sim({"study", "report", kPetcExample, dir + "/report", "--seeds", "2", "--no-plots", "--trace", "5,6'"});
  ASSERT_EQ(rep.exit_code, 0) << rep.output;
  const test::CommandResult run = petc_sim({"study", "run", kPetcExample, "--seeds", "2", "--out", dir + "/run", "--json", dir + "/run.json"});
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const nlohmann::json rj = nlohmann::json::parse(test::read_file(dir + "/report/report.json"));
  const nlohmann::json uj = nlohmann::json::parse(test::read_file(dir + "/run.json"));
  EXPECT_EQ(rj.at("approaches"), uj.at("approaches"));
  EXPECT_NE(test::read_file(dir + "/report/report.md").find(uj.at("markdown").get<std::string>()), std::string::npos);
  EXPECT_TRUE(std::filesystem::exists(dir + "/report/table_summary.csv"));
  ASSERT_EQ(rj.at("traces").size(), 2U);
  for (const auto& [name, t] : rj.at("traces").items()) EXPECT_TRUE(t.at("same_cost_as_sweep").get<bool>()) << name;
  const std::string csv = test::read_file(dir + "/report/trace_7_6_.csv");  // "6'" as a file name
  EXPECT_EQ(static_cast<std::size_t>(std::count(csv.begin(), csv.end(), '\n')), 465U);  // the header + one row per period
  EXPECT_FALSE(std::filesystem::exists(dir + "/report/trace_1_1.csv"));

  // bench: the same runs (per approach the same mean GPI), at least one event per period.
  const nlohmann::json b = petc_bench(*petc_map_text(petc_example_json()), 2, 2);
  EXPECT_EQ(b.at("runs"), 14);
  EXPECT_GE(b.at("events").get<double>(), 14.0 * 464);
  EXPECT_NEAR(b.at("simulated_s").get<double>(), 14 * 464 * 20e-6, 1e-12);
  for (const auto& [name, a] : uj.at("approaches").items()) {
    const double x = b.at("per_approach").at(name).at("cost_mean").get<double>(), y = a.at("cost_mean").get<double>();
    EXPECT_LE(std::fabs(x - y), 1e-15 * y) << name;  // measured: equal (a sum over 2 runs, both ways)
  }
}

TEST(StudyPetc, RefusalsNameTheField) {
  struct Case {
    const char* field;
    std::function<void(nlohmann::json&)> edit;
  };
  const std::vector<Case> cases = {
      {"approaches[0].kind", [](nlohmann::json& j) { j["approaches"][0]["kind"] = "smith"; }},
      {"approaches[0].params.sigma_s", [](nlohmann::json& j) { j["approaches"][0]["params"]["sigma_s"] = 1e-3; }},
      {"approaches[1].params.noise", [](nlohmann::json& j) { j["approaches"][1]["params"]["noise"] = 0.5; }},
      {"approaches[1].params.t_hold", [](nlohmann::json& j) { j["approaches"][1]["params"]["t_hold"] = 1; }},
      {"approaches[1].params.sigma_s",
       [](nlohmann::json& j) { j["nodes"][0]["trigger"] = {{"rule", "periodic"}, {"every", 1}}; }},
      {"nodes[0].trigger.k_max", [](nlohmann::json& j) { j["nodes"][0]["trigger"]["k_max"] = 100; }},
      {"nodes[1].trigger.k_ref_max", [](nlohmann::json& j) { j["nodes"][1]["trigger"]["k_ref_max"] = 3; }},
      {"nodes[0].trigger.rule",
       [](nlohmann::json& j) { j["nodes"][0]["trigger"] = {{"rule", "send_on_delta"}, {"delta", {0.1}}}; }},
      {"nodes[0].trigger.every", [](nlohmann::json& j) { j["nodes"][0]["trigger"] = {{"rule", "periodic"}, {"every", 2}}; }},
      {"nodes[0].trigger",
       [](nlohmann::json& j) {
         for (nlohmann::json& a : j["approaches"])
           if (a["kind"] != "tts") a["params"].update({{"sigma_s", 1e-7}, {"delta_s", 1e-7}});
       }},
      {"nodes[1].mode", [](nlohmann::json& j) { j["nodes"][1] = {{"name", "controller"}, {"role", "controller"}, {"address", 2}, {"mode", "timer"}, {"period_us", 20}}; }},
      {"nodes[0].period_us", [](nlohmann::json& j) { j["nodes"][0]["period_us"] = 40; }},
      {"nodes[2].clock_offset_us", [](nlohmann::json& j) { j["nodes"][2]["clock_offset_us"] = 5; }},
      {"nodes[2].trigger", [](nlohmann::json& j) { j["nodes"][2]["trigger"] = {{"rule", "periodic"}, {"every", 1}}; }},
      {"nodes", [](nlohmann::json& j) {
         j["nodes"].erase(2);
         j["links"].erase(1);
       }},
      {"links", [](nlohmann::json& j) { j["links"].erase(1); }},
      {"links[0].delay", [](nlohmann::json& j) { j["links"][0]["delay"] = {{"model", "constant"}, {"delay_us", 5}}; }},
      {"links[1].loss", [](nlohmann::json& j) { j["links"][1]["loss"] = {{"model", "bernoulli"}, {"p", 0.01}}; }},
      {"scenarios[0].links.ca.delay",
       [](nlohmann::json& j) { j["scenarios"][0]["links"]["ca"]["delay"] = {{"model", "uniform"}, {"min_us", 0}, {"max_us", 5}}; }},
      {"links[1].to", [](nlohmann::json& j) { j["links"][1]["to"] = "sensor"; }},
      {"plant.file", [](nlohmann::json& j) { j["plant"]["file"] = "../../../lut_gen/plants/networked_board.json"; }},
      {"plant.file", [](nlohmann::json& j) { j["plant"]["file"] = "../../../lut_gen/plants/sinopoli_dropping.json"; }},
      {"duration_s", [](nlohmann::json& j) { j["duration_s"] = 0.00929; }},
      {"scenarios[0].duration_s", [](nlohmann::json& j) { j["scenarios"][0]["duration_s"] = 1e-5; }},
      {"reference.kind", [](nlohmann::json& j) { j["reference"] = {{"kind", "square"}, {"amplitude_volts", 1}, {"period_s", 0.01}}; }},
      {"reference.steps", [](nlohmann::json& j) { j["reference"] = {{"kind", "steps"}, {"steps", {{0, 1}, {0.001, 2}}}}; }},
      {"scenarios[0].reference.steps",
       [](nlohmann::json& j) { j["scenarios"][0]["reference"] = {{"kind", "steps"}, {"steps", {{0.001, 1}}}}; }},
      {"scenarios[0].params.ratio", [](nlohmann::json& j) { j["scenarios"][0]["params"]["ratio"] = 3; }},  // 1 slow + 2 fast
      {"scenarios[0].params.ratio", [](nlohmann::json& j) { j["scenarios"][0]["params"]["ratio"] = 17; }},
      {"scenarios[0].params.noise", [](nlohmann::json& j) { j["scenarios"][0]["params"]["noise"] = 2; }},
      {"scenarios[0].params.sigma_w", [](nlohmann::json& j) { j["scenarios"][0]["params"]["sigma_w"] = -1; }},
      {"loops", [](nlohmann::json& j) {
         j["loops"] = {{{"name", "a"}, {"plant", j["plant"]}, {"sensor", "sensor"}, {"controller", "controller"}, {"actuator", "actuator"}}};
         j.erase("plant");
       }},
  };
  ASSERT_NO_THROW(static_cast<void>(petc_map_text(petc_example_json())));
  for (const Case& c : cases) {
    nlohmann::json j = petc_example_json();
    c.edit(j);
    try {
      static_cast<void>(petc_map_text(j));
      ADD_FAILURE() << c.field << ": accepted";
    } catch (const engine::InputError& e) {
      EXPECT_NE(std::string(e.what()).find("field '" + std::string(c.field) + "'"), std::string::npos) << c.field << ": " << e.what();
      EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
    }
  }
}

TEST(StudyPetc, CommandsRefuseBeforeWritingAnything) {
  const std::string dir = test::made_dir("oneshot_study_petc", "refuse");
  nlohmann::json j = petc_example_json();
  j["approaches"][0]["kind"] = "smith";
  j["plant"]["file"] = std::string(ONESHOT_STUDY_EXAMPLES_DIR) + "/../../../lut_gen/plants/hdd_numre.json";
  const std::string bad = dir + "/bad.json";
  util::write_text(bad, j.dump());
  const std::vector<std::vector<std::string>> argvs = {
      {"study", "run", bad, "--out", dir + "/no"},
      {"study", "report", bad, dir + "/no"},
      {"study", "bench", bad},
      {"study", "run", kPetcExample, "--out", dir + "/no", "--analytic"},
      {"study", "run", kPetcExample, "--out", dir + "/no", "--max-duration", "1"},
      {"study", "report", kPetcExample, dir + "/no", "--trace", "7"},
      {"study", "report", kPetcExample, dir + "/no", "--trace", "1,1"},
      {"study", "report", kPetcExample, dir + "/no", "--max-duration", "1"},
  };
  const std::vector<std::string> fields = {"approaches[0].kind", "approaches[0].kind", "approaches[0].kind", "--analytic",
                                           "--max-duration",     "--trace",            "--trace",            "--max-duration"};
  for (std::size_t i = 0; i < argvs.size(); ++i) {
    const test::CommandResult r = petc_sim(argvs[i]);
    EXPECT_NE(r.exit_code, 0) << argvs[i][1];
    EXPECT_NE(r.output.find("field '" + fields[i] + "'"), std::string::npos) << r.output;
    EXPECT_FALSE(std::filesystem::exists(dir + "/no")) << argvs[i][1] << " " << fields[i];
  }
  const test::CommandResult c = petc_sim({"study", "check", bad});
  EXPECT_NE(c.exit_code, 0);
  EXPECT_NE(c.output.find("cannot run: field 'approaches[0].kind'"), std::string::npos) << c.output;
}

}  // namespace
}  // namespace oneshot::study
