/// @file study_sod_test.cpp
/// @brief "study": "sod" files (sim_host/study/study_sod_*.cpp): the shipped example against
///        `oneshot-sim sod table` on the same seeds, the same bytes on 1 and 2 threads and from
///        merged shards, the refusals naming the field (one line, nothing written), and what
///        holds exactly on a nearly noise-free plant.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "oneshot/engine/study_file.hpp"
#include "oneshot/engine/sweep.hpp"
#include "oneshot/util/output_files.hpp"
#include "study_sod_runner.hpp"
#include "study_sod_study.hpp"
#include "support/run_command.hpp"
#include "support/temp_files.hpp"

namespace oneshot::study {
namespace {

const std::string kSodExample = std::string(ONESHOT_STUDY_EXAMPLES_DIR) + "/sod.json";

nlohmann::json sod_example_json() { return nlohmann::json::parse(test::read_file(kSodExample)); }

/// `j` parsed as a file at `source` (relative plant paths from its folder) and mapped.
std::shared_ptr<const SodStudy> sod_map_text(const nlohmann::json& j, const std::string& source = kSodExample) {
  return map_sod_study(engine::parse_study(j.dump(), source, &sod_schema(), std::filesystem::path(source).parent_path().string()));
}

/// |a − b| ≤ rel |b|.
void sod_expect_close(double a, double b, double rel, const std::string& what) {
  EXPECT_LE(std::fabs(a - b), rel * std::fabs(b)) << what << ": " << a << " vs " << b;
}

TEST(StudySod, ExampleGivesTheSodTable) {
  // Per approach and loss rate: e1, e2, NEES and the packets of both nodes as `sod table` on the
  // same seeds, and msod's n_t of the same design. Measured: equal bit for bit (relative
  // difference 0: the same runs, the same summation); tolerance 1e-12.
  for (const char* seeds : {"2", "4"}) {
    const std::string dir = test::made_dir("oneshot_study_sod", std::string("oracle") + seeds);
    const test::CommandResult a = test::run_command({ONESHOT_SIM_PATH, "study", "run", kSodExample, "--seeds", seeds, "--threads", "2",
                                                     "--out", dir + "/study", "--json", dir + "/study.json"});
    ASSERT_EQ(a.exit_code, 0) << a.output;
    const test::CommandResult b = test::run_command({ONESHOT_SIM_PATH, "sod", "table", "--seeds", seeds, "--threads", "2", "--no-plots",
                                                     "--out", dir + "/table", "--json", dir + "/table.json"});
    ASSERT_EQ(b.exit_code, 0) << b.output;
    const nlohmann::json s = nlohmann::json::parse(test::read_file(dir + "/study.json"));
    const nlohmann::json t = nlohmann::json::parse(test::read_file(dir + "/table.json"));
    ASSERT_EQ(t.at("rows").size(), 16U);
    ASSERT_EQ(s.at("per_scenario").size(), 4U);
    for (const nlohmann::json& row : t.at("rows")) {
      const std::string a_name = row.at("configuration").get<std::string>();
      const double xi = row.at("loss").get<double>();
      std::size_t x = 0;
      while (x < 4 && s.at("per_scenario")[x].at("loss").get<double>() != xi) ++x;
      ASSERT_LT(x, 4U) << xi;
      const nlohmann::json& e = s.at("per_scenario")[x];
      const std::string what = a_name + " xi " + std::to_string(xi) + " seeds " + seeds;
      sod_expect_close(e.at("e1").at(a_name).at("mean"), row.at("e")[0].at("mean"), 1e-12, what + " e1");
      sod_expect_close(e.at("e2").at(a_name).at("mean"), row.at("e")[1].at("mean"), 1e-12, what + " e2");
      sod_expect_close(e.at("nees").at(a_name).at("mean"), row.at("nees").at("mean"), 1e-12, what + " NEES");
      for (std::size_t i = 0; i < 2; ++i) {
        sod_expect_close(e.at("packets").at(a_name)[i].at("mean"), row.at("packets")[i].at("mean"), 1e-12, what + " packets");
        sod_expect_close(e.at("losses").at(a_name)[i].at("mean"), row.at("losses")[i].at("mean"), 1e-12, what + " losses");
      }
      if (row.contains("n_t")) {  // msod: the design's n_t ran
        std::size_t ai = 0;
        while (s.at("settings")[ai].at("name") != a_name) ++ai;
        EXPECT_EQ(s.at("settings")[ai].at("per_scenario")[x].at("n_t"), row.at("n_t")) << what;
      }
    }
    // The per-link counters: delivered + lost = sent; the periodic sender sends every sample.
    const nlohmann::json& l = s.at("links").at("periodic").at("node1");
    EXPECT_EQ(l.at("sent").get<double>(), 4.0 * std::stod(seeds) * 5001);
    EXPECT_EQ(l.at("delivered").get<double>() + l.at("lost").get<double>(), l.at("sent").get<double>());
    EXPECT_EQ(s.at("approaches").at("sod-held").at("ratio_to_sod-held").get<double>(), 1.0);
  }
}

TEST(StudySod, SameBytesOnOneAndTwoThreadsAndFromMergedShards) {
  const std::string dir = test::made_dir("oneshot_study_sod", "bytes");
  const auto run = [&](std::vector<std::string> extra) {
    std::vector<std::string> argv{ONESHOT_SIM_PATH, "study", "run", kSodExample, "--seeds", "3"};
    argv.insert(argv.end(), extra.begin(), extra.end());
    const test::CommandResult r = test::run_command(argv);
    EXPECT_EQ(r.exit_code, 0) << r.output;
  };
  run({"--threads", "1", "--out", dir + "/t1", "--json", dir + "/t1.json"});
  run({"--threads", "2", "--out", dir + "/t2", "--json", dir + "/t2.json"});
  const std::string one = test::read_file(dir + "/t1.json");
  ASSERT_FALSE(one.empty());
  EXPECT_EQ(one, test::read_file(dir + "/t2.json"));
  run({"--threads", "1", "--shard", "0/2", "--out", dir + "/sh"});
  run({"--threads", "2", "--shard", "1/2", "--out", dir + "/sh"});
  const test::CommandResult m = test::run_command({ONESHOT_SIM_PATH, "merge", dir + "/sh/run.shard-0-of-2.json",
                                                   dir + "/sh/run.shard-1-of-2.json", "--out", dir + "/m", "--json", dir + "/m.json"});
  ASSERT_EQ(m.exit_code, 0) << m.output;
  EXPECT_EQ(one, test::read_file(dir + "/m.json"));
  EXPECT_EQ(test::read_file(dir + "/t1/runs.csv"), test::read_file(dir + "/m/runs.csv"));
}

TEST(StudySod, RefusalsNameTheField) {
  struct Case {
    const char* field;
    std::function<void(nlohmann::json&)> edit;
  };
  const nlohmann::json periodic_trigger = {{"rule", "periodic"}, {"every", 1}};
  const auto drop_node2 = [](nlohmann::json& j) {  // link node2 and the scenarios' overrides of it
    j["links"].erase(1);
    for (nlohmann::json& x : j["scenarios"])
      if (x.contains("links")) x["links"].erase("node2");
  };
  const std::vector<Case> cases = {
      {"approaches[0].kind", [](nlohmann::json& j) { j["approaches"][0]["kind"] = "kalman"; }},
      {"approaches[0].params.mu", [](nlohmann::json& j) { j["approaches"][0]["params"]["mu"] = 3; }},
      {"approaches[2].params.mu", [](nlohmann::json& j) { j["approaches"][2]["params"]["mu"] = 1; }},
      {"approaches[2].params.every", [](nlohmann::json& j) { j["approaches"][2]["params"]["every"] = 2; }},
      {"approaches[3].params.every", [](nlohmann::json& j) { j["approaches"][3]["params"]["every"] = 1.5; }},
      {"approaches[3].params.mu", [](nlohmann::json& j) { j["approaches"][3]["params"]["mu"] = 3; }},
      {"approaches[0].params.t_hold", [](nlohmann::json& j) { j["approaches"][0]["params"]["t_hold"] = 1; }},
      {"nodes[3].role",
       [](nlohmann::json& j) { j["nodes"].push_back({{"name", "act"}, {"role", "actuator"}, {"address", 4}, {"mode", "timer"}, {"period_us", 10000}}); }},
      {"nodes[2].role", [](nlohmann::json& j) { j["nodes"][1]["role"] = "controller"; j["nodes"][1].erase("trigger"); }},
      {"nodes", [drop_node2](nlohmann::json& j) { drop_node2(j); j["nodes"].erase(1); }},
      {"nodes[0].trigger", [periodic_trigger](nlohmann::json& j) { j["nodes"][0]["trigger"] = periodic_trigger; }},
      {"nodes[0].trigger", [](nlohmann::json& j) { j["nodes"][0].erase("trigger"); }},
      {"nodes[2].trigger", [](nlohmann::json& j) { j["nodes"][2]["trigger"] = {{"rule", "send_on_delta"}, {"delta", {0.5}}}; }},
      {"nodes[1].trigger.delta", [](nlohmann::json& j) { j["nodes"][1]["trigger"]["delta"] = {0.5, 0.5}; }},
      {"nodes[1].trigger.time_steps", [](nlohmann::json& j) { j["nodes"][1]["trigger"]["time_steps"] = 10; }},
      {"nodes[0].period_us", [](nlohmann::json& j) { j["nodes"][0]["period_us"] = 20000; }},
      {"nodes[2].mode", [](nlohmann::json& j) { j["nodes"][2] = {{"name", "estimator"}, {"role", "controller"}, {"address", 3}, {"mode", "arrival"}}; }},
      {"nodes[2].clock_offset_us", [](nlohmann::json& j) { j["nodes"][2]["clock_offset_us"] = 100; }},
      {"links", [drop_node2](nlohmann::json& j) { drop_node2(j); }},
      {"links[1]", [](nlohmann::json& j) { j["links"][1]["from"] = "node1"; }},  // the parser's: a second link node1 -> estimator
      {"links[1].to",
       [](nlohmann::json& j) {
         j["links"][1]["from"] = "estimator";
         j["links"][1]["to"] = "node2";
       }},
      {"links[0].to", [](nlohmann::json& j) { j["links"][0]["to"] = "node2"; }},
      {"links[0].delay", [](nlohmann::json& j) { j["links"][0]["delay"] = {{"model", "constant"}, {"delay_us", 1000}}; }},
      {"scenarios[1].links.node1.delay", [](nlohmann::json& j) { j["scenarios"][1]["links"]["node1"]["delay"] = {{"model", "constant"}, {"delay_us", 5}}; }},
      {"links[0].loss",
       [](nlohmann::json& j) {
         j["links"][0]["loss"] = {{"model", "gilbert_elliott"}, {"p_good_to_bad", 0.05}, {"p_bad_to_good", 0.5}};
       }},
      {"scenarios[2].links.node2.loss", [](nlohmann::json& j) { j["scenarios"][2]["links"]["node2"]["loss"]["p"] = 0.3; }},
      {"links[1].loss", [](nlohmann::json& j) { j["links"][1]["loss"] = {{"model", "bernoulli"}, {"p", 0.1}}; }},
      {"duration_s", [](nlohmann::json& j) { j["duration_s"] = 0.015; }},
      {"scenarios[0].duration_s", [](nlohmann::json& j) { j["scenarios"][0]["duration_s"] = 0.0001; }},
      {"scenarios[0].params.lambda", [](nlohmann::json& j) { j["scenarios"][0]["params"] = {{"lambda", 0.5}}; }},
      {"reference", [](nlohmann::json& j) { j["reference"] = {{"kind", "square"}, {"amplitude_volts", 1}, {"period_s", 2}}; }},
      {"plant.file", [](nlohmann::json& j) { j["plant"]["file"] = "../../../lut_gen/plants/sinopoli_dropping.json"; }},
      {"plant.continuous",
       [](nlohmann::json& j) {
         j["plant"] = {{"continuous", {{"A", {{0, 1}, {-0.2, -0.2}}}, {"B", {{0}, {6}}}, {"C", {{1, 0}, {0, 1}}}, {"Q_c", {{0.01, 0}, {0, 0.01}}}}}};
       }},
      {"study", [](nlohmann::json& j) { j["study"] = "dropping"; }},
      {"nodes[0].trigger.time_steps",  // a time rule no approach runs (only msod's sender takes it)
       [](nlohmann::json& j) {
         j["nodes"][0]["trigger"]["time_steps"] = 50;
         j["nodes"][1]["trigger"]["time_steps"] = 50;
         j["approaches"].erase(2);
       }},
  };
  ASSERT_NO_THROW(static_cast<void>(sod_map_text(sod_example_json())));
  {  // a range bound is printed as itself: mu must exceed 1, so its lower bound is not "1"
    nlohmann::json j = sod_example_json();
    j["approaches"][2]["params"]["mu"] = 1;
    try {
      static_cast<void>(sod_map_text(j));
      ADD_FAILURE() << "mu = 1 accepted";
    } catch (const engine::InputError& e) {
      EXPECT_NE(std::string(e.what()).find("[1.000001, 1e+06]"), std::string::npos) << e.what();
    }
  }
  for (const Case& c : cases) {
    nlohmann::json j = sod_example_json();
    c.edit(j);
    try {
      static_cast<void>(sod_map_text(j));
      ADD_FAILURE() << c.field << ": accepted";
    } catch (const engine::InputError& e) {
      EXPECT_NE(std::string(e.what()).find("field '" + std::string(c.field) + "'"), std::string::npos) << c.field << ": " << e.what();
      EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
    }
  }
}

TEST(StudySod, CommandsRefuseOnOneLineAndWriteNothing) {
  const std::string dir = test::made_dir("oneshot_study_sod", "refuse");
  nlohmann::json j = sod_example_json();
  j["approaches"][1]["kind"] = "kalman";
  j["plant"]["file"] = std::string(ONESHOT_STUDY_EXAMPLES_DIR) + "/" + j["plant"]["file"].get<std::string>();
  const std::string bad = dir + "/bad.json";
  util::write_text(bad, j.dump());
  const std::vector<std::vector<std::string>> commands = {
      {ONESHOT_SIM_PATH, "study", "run", bad, "--out", dir + "/out", "--json", dir + "/out.json"},
      {ONESHOT_SIM_PATH, "study", "report", bad, dir + "/out"},
      {ONESHOT_SIM_PATH, "study", "bench", bad, "--json", dir + "/out.json"},
      {ONESHOT_SIM_PATH, "study", "run", kSodExample, "--out", dir + "/out", "--analytic"},
      {ONESHOT_SIM_PATH, "study", "run", kSodExample, "--out", dir + "/out", "--max-duration", "1"},
      {ONESHOT_SIM_PATH, "study", "report", kSodExample, dir + "/out", "--trace", "nope"},
  };
  const char* const fields[] = {"approaches[1].kind", "approaches[1].kind", "approaches[1].kind", "--analytic", "--max-duration", "--trace"};
  for (std::size_t i = 0; i < commands.size(); ++i) {
    const test::CommandResult r = test::run_command(commands[i]);
    EXPECT_NE(r.exit_code, 0) << fields[i];
    EXPECT_NE(r.output.find("field '" + std::string(fields[i]) + "'"), std::string::npos) << r.output;
    EXPECT_EQ(r.output.find('\n'), r.output.size() - 1) << r.output;  // one line
    EXPECT_FALSE(std::filesystem::exists(dir + "/out")) << fields[i];
    EXPECT_FALSE(std::filesystem::exists(dir + "/out.json")) << fields[i];
  }
  // study check: the resolution, then the refusal as the last line, non-zero exit.
  const test::CommandResult c = test::run_command({ONESHOT_SIM_PATH, "study", "check", bad});
  EXPECT_NE(c.exit_code, 0);
  EXPECT_NE(c.output.find("cannot run: field 'approaches[1].kind'"), std::string::npos) << c.output;
}

TEST(StudySod, CheckGivesTheDesign) {
  const std::string dir = test::made_dir("oneshot_study_sod", "check");
  test::CommandOptions to_file;
  to_file.stdout_path = dir + "/check.json";
  const test::CommandResult c = test::run_command({ONESHOT_SIM_PATH, "study", "check", kSodExample, "--json", "-"}, to_file);
  ASSERT_EQ(c.exit_code, 0) << c.output;
  const nlohmann::json r = nlohmann::json::parse(test::read_file(dir + "/check.json"));
  EXPECT_EQ(r.at("runs_with"), "sod");
  const nlohmann::json& d = r.at("sod");
  // A_d = e^{AT}: det A_d = e^{tr(A) T} (Jacobi), tr A = -0.2, T = 10 ms; measured error 1e-16.
  const double det = d.at("A_d")[0][0].get<double>() * d.at("A_d")[1][1].get<double>() -
                     d.at("A_d")[0][1].get<double>() * d.at("A_d")[1][0].get<double>();
  EXPECT_NEAR(det, std::exp(-0.2 * 0.01), 1e-14);
  EXPECT_EQ(d.at("R_diag"), nlohmann::json({0.01, 0.01}));
  // One design per msod scenario with loss (xi = 0: no time rule), dt* xi the same at every xi (§5).
  ASSERT_EQ(d.at("designs").size(), 3U);
  const double first = d.at("designs")[0].at("delta_t_s")[0].get<double>() * d.at("designs")[0].at("loss").get<double>();
  for (const nlohmann::json& e : d.at("designs"))
    EXPECT_NEAR(e.at("delta_t_s")[0].get<double>() * e.at("loss").get<double>(), first, 1e-9 * first);
  EXPECT_EQ(d.at("approaches")[2].at("per_scenario")[0].at("n_t"), nlohmann::json({0, 0}));
}

/// A plant file like the study's with Q_c = 1e-24 I, R = 1e-20 I (nearly noise-free: the state
/// moves by ~1e-12 over a run, a sample by 1e-10) and the example on it, in `dir`.
std::string quiet_study(const std::string& dir, const nlohmann::json& scenarios) {
  nlohmann::json p = nlohmann::json::parse(test::read_file(std::string(ONESHOT_STUDY_EXAMPLES_DIR) + "/../../../lut_gen/plants/send_on_delta_oscillator.json"));
  p["noise"]["process_intensity"] = {{1e-24, 0}, {0, 1e-24}};
  p["noise"]["measurement_covariance"] = {{1e-20, 0}, {0, 1e-20}};
  util::write_text(dir + "/quiet_plant.json", p.dump());
  nlohmann::json j = sod_example_json();
  j["plant"]["file"] = "quiet_plant.json";
  j["duration_s"] = 20;
  j["scenarios"] = scenarios;
  const std::string path = dir + "/quiet.json";
  util::write_text(path, j.dump());
  return path;
}

TEST(StudySod, NearlyNoiseFreeInvariants) {
  const std::string dir = test::made_dir("oneshot_study_sod", "quiet");
  const nlohmann::json scen = nlohmann::json::array({{{"name", "still"}, {"params", {{"amplitude", 0}}}}, {{"name", "step"}}});
  const std::string path = quiet_study(dir, scen);
  const std::shared_ptr<const SodStudy> s = sod_map_text(nlohmann::json::parse(test::read_file(path)), path);
  const engine::SweepResults r = run_sod_sweep(*s, 2, 1, engine::Shard{});
  const std::size_t n = 2000;  // steps of 20 s at T = 10 ms
  const auto v = [&](std::size_t a, std::size_t x, std::size_t k, const char* m) { return r.at(a, x, k, r.metric(m)); };
  // The oracle: the noise-free step response x_{k+1} = A_d x_k + B_d u from x_0 = 0 and plain
  // send-on-delta on it (the first sample, then |y - y_last| > dy) count the packets exactly.
  std::size_t sends[2] = {0, 0};
  {
    double x[2] = {0, 0}, last[2] = {0, 0};
    for (std::size_t k = 0; k <= n; ++k) {
      for (std::size_t i = 0; i < 2; ++i)
        if (k == 0 || std::fabs(x[i] - last[i]) > 0.5) {
          ++sends[i];
          last[i] = x[i];
        }
      const double x0 = s->model.a_d(0, 0) * x[0] + s->model.a_d(0, 1) * x[1] + s->model.b_d(0, 0);
      const double x1 = s->model.a_d(1, 0) * x[0] + s->model.a_d(1, 1) * x[1] + s->model.b_d(1, 0);
      x[0] = x0;
      x[1] = x1;
    }
  }
  ASSERT_GT(sends[0], 20U);
  for (std::size_t k = 0; k < 2; ++k) {
    for (std::size_t a = 0; a < 3; ++a) {  // sod-held, sod-kf, msod (xi = 0: n_t = 0, plain SOD)
      // Input 0: the outputs never move by dy, only the first sample goes out.
      EXPECT_EQ(v(a, 0, k, "sends1"), 1.0);
      EXPECT_EQ(v(a, 0, k, "sends2"), 1.0);
      EXPECT_EQ(v(a, 1, k, "sends1"), static_cast<double>(sends[0])) << a;
      EXPECT_EQ(v(a, 1, k, "sends2"), static_cast<double>(sends[1])) << a;
    }
    for (std::size_t x = 0; x < 2; ++x) {
      // msod at xi = 0 is sod-held, bit for bit; no loss: nothing lost or detected.
      for (const char* m : {"cost", "e1", "e2", "nees", "sends1", "sends2"}) EXPECT_EQ(v(2, x, k, m), v(0, x, k, m)) << m;
      for (std::size_t a = 0; a < 4; ++a)
        for (const char* m : {"lost1", "lost2", "detected1", "detected2", "time_sends1", "time_sends2"}) EXPECT_EQ(v(a, x, k, m), 0.0);
      // The periodic sender sends every sample.
      EXPECT_EQ(v(3, x, k, "sends1"), static_cast<double>(n + 1));
      // With Q_c ~ 0 every filter's model predicts the state exactly: e_i is at the measurement
      // noise's scale R = 1e-20 (measured at most 7.3e-21; tolerance 5e-20).
      for (std::size_t a = 0; a < 4; ++a) {
        EXPECT_LE(v(a, x, k, "e1"), 5e-20) << a;
        EXPECT_LE(v(a, x, k, "e2"), 5e-20) << a;
      }
    }
  }
}

}  // namespace
}  // namespace oneshot::study
