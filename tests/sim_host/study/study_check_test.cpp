/// @file study_check_test.cpp
/// @brief `study check`: the resolution of a file (designs, link summaries, CAN load and
///        bounds, the grid) against closed forms, its refusals naming the field, and the
///        command line (one line, non-zero exit, nothing written on bad input).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "ncs_model.hpp"
#include "oneshot/engine/can_bus.hpp"
#include "oneshot/engine/delay_model.hpp"
#include "oneshot/engine/random_stream.hpp"
#include "oneshot/engine/study_file.hpp"
#include "study_check.hpp"
#include "study_dropping_runner.hpp"
#include "study_ncs_runner.hpp"
#include "study_sod_runner.hpp"
#include "study_oneshot_study.hpp"
#include "study_petc_study.hpp"
#include "support/run_command.hpp"
#include "support/temp_files.hpp"

namespace oneshot::study {
namespace {

nlohmann::json read_json(const std::string& path) { return nlohmann::json::parse(test::read_file(path)); }

engine::StudyFile parse(const nlohmann::json& j, const std::string& like) {
  return engine::parse_study(j.dump(), like, nullptr, std::filesystem::path(like).parent_path().string());
}

const std::string kNcsExample = std::string(ONESHOT_STUDY_EXAMPLES_DIR) + "/ncs.json";

TEST(StudyCheck, NcsFileResolvesToTheDesignOfItsPlantFile) {
  const nlohmann::json r = resolve_study(engine::load_study(kNcsExample, nullptr));
  EXPECT_EQ(r.at("plant").at("n"), 2);
  EXPECT_EQ(r.at("plant").at("m"), 1);
  EXPECT_EQ(r.at("plant").at("p"), 2);
  const auto ctx = ncs::Context::load("");
  for (const nlohmann::json& a : r.at("approaches")) {
    if (a.at("kind") == "S+") {  // its own gain per scenario (study check adds it)
      EXPECT_FALSE(a.contains("lqr_gain"));
      continue;
    }
    for (std::size_t j = 0; j < 2; ++j) EXPECT_EQ(a.at("lqr_gain")[0][j].get<double>(), ctx->design().l(0, j));
    const double rho = a.at("closed_loop_spectral_radius").get<double>();
    EXPECT_GT(rho, 0);
    EXPECT_LT(rho, 1);
    const std::string kind = a.at("kind");
    EXPECT_EQ(a.contains("kalman_gain"), kind == "AK" || kind == "AKx" || kind == "AKl" || kind == "SK" || kind == "IK") << kind;
  }
  // Uniform whole-µs legs: mean (min + max)/2, no loss; d = 14 overrides of scenario 1.
  const nlohmann::json& sc = r.at("links")[1];
  EXPECT_EQ(sc.at("base").at("delay").at("mean_us").get<double>(), 2250);
  EXPECT_EQ(sc.at("base").at("delay").at("max_us").get<double>(), 4000);
  EXPECT_EQ(sc.at("base").at("loss_probability").get<double>(), 0);
  EXPECT_EQ(sc.at("scenarios").at("a0.2-T2-d14-s1").at("delay").at("mean_us").get<double>(), 7250);
  EXPECT_EQ(r.at("grid").at("runs"), 9 * 10 * 50);
}

TEST(StudyCheck, ExampleFileGivesLinkSummariesAndCanBounds) {
  const engine::StudyFile f = engine::load_study(ONESHOT_ENGINE_EXAMPLE_STUDY, nullptr);
  const nlohmann::json r = resolve_study(f);
  EXPECT_FALSE(r.at("plant").at("designed").get<bool>());
  // Gilbert–Elliott p = 0.01, r = 0.3, k = 0, h = 1: π_B = p/(p + r).
  const nlohmann::json& sc = r.at("links")[0];
  EXPECT_NEAR(sc.at("base").at("loss_probability").get<double>(), 0.01 / 0.31, 1e-15);
  // Scenario d14-heavy: lognormal median 3 ms, σ 0.6, shift 0.5 ms: mean shift + m e^{σ²/2}.
  EXPECT_NEAR(sc.at("scenarios").at("d14-heavy").at("delay").at("mean_us").get<double>(), 500 + 3000 * std::exp(0.18), 1e-9);
  EXPECT_TRUE(sc.at("scenarios").at("d14-heavy").at("delay").at("max_us").is_null());
  // Bus can0 at 500 kbit/s: 8-byte standard frames of 135 bits = 270 µs; background every
  // 5 ms, the loop's ca message every 50 ms (the sensor's period).
  const nlohmann::json& bus = r.at("buses")[0];
  EXPECT_EQ(engine::can_frame_bits(8, false), 135);
  EXPECT_NEAR(bus.at("load").get<double>(), 270.0 / 5000 + 270.0 / 50000, 1e-15);
  ASSERT_EQ(bus.at("messages").size(), 2U);
  const nlohmann::json& ca = bus.at("messages")[1];
  EXPECT_EQ(ca.at("name"), "ca");
  // ca is sent by the controller on arrival: released sc delay + τ_c after the sensor's timer,
  // sc U[500, 4000] µs, τ_c U[1, 5] ms: jitter (4000 + 5000) − (500 + 1000) µs. It outranks the
  // background (id 256): blocked by one background frame at most, no higher-priority
  // interference: R = J + B + C = J + 270 + 270 µs.
  const ncs::Timing t;
  const double j_ca = static_cast<double>(4000 + t.compute_max_us - (500 + t.compute_min_us));
  EXPECT_EQ(ca.at("jitter_us").get<double>(), j_ca);
  EXPECT_EQ(ca.at("worst_response_us").get<double>(), j_ca + 270 + 270);
  // The background: one ca frame of interference (J_ca + w < T_ca) and its own jitter 500 µs:
  // R = J + C + C.
  EXPECT_EQ(bus.at("messages")[0].at("worst_response_us").get<double>(), 500 + 270 + 270);
  // Scenario d14-heavy: sc lognormal, no upper bound: ca's jitter and response unbounded, and
  // so is the background's (lower priority: ca's interference on it has no bound).
  const nlohmann::json& heavy = bus.at("scenarios").at("d14-heavy");
  EXPECT_TRUE(heavy[1].at("jitter_us").is_null());
  EXPECT_TRUE(heavy[1].at("worst_response_us").is_null());
  EXPECT_TRUE(heavy[0].at("worst_response_us").is_null());
  EXPECT_FALSE(heavy[0].at("schedulable").get<bool>());
  EXPECT_EQ(bus.at("scenarios").size(), 1U);  // d4 keeps the file's sc
}

TEST(StudyCheck, ArrivalSendersJitterAddsUpAlongTheirChain) {
  // The actuator on arrival sends "as" on the bus: sensor timer → sc → controller (τ_c) → ca
  // → actuator (τ_c) → as. Jitter = (max sc + max ca + 2 max τ_c) − (min sc + min ca + 2 min τ_c).
  nlohmann::json j = read_json(ONESHOT_ENGINE_EXAMPLE_STUDY);
  j["links"][1] = {{"name", "ca"}, {"from", "controller"}, {"to", "actuator"},
                   {"delay", {{"model", "uniform"}, {"min_us", 200}, {"max_us", 700}}}};
  j["links"].push_back({{"name", "as"}, {"from", "actuator"}, {"to", "sensor"}, {"bus", "can0"}, {"id", 17}});
  j["scenarios"].erase(1);
  const nlohmann::json r = resolve_study(parse(j, ONESHOT_ENGINE_EXAMPLE_STUDY));
  const nlohmann::json& as = r.at("buses")[0].at("messages")[1];
  ASSERT_EQ(as.at("name"), "as");
  const ncs::Timing t;
  const double expect = static_cast<double>((4000 + 700 + 2 * t.compute_max_us) - (500 + 200 + 2 * t.compute_min_us));
  EXPECT_EQ(as.at("jitter_us").get<double>(), expect);
  // A Poisson leg has no bound (draw() applies no cap): no cap reported, unbounded jitter.
  j["links"][1]["delay"] = {{"model", "poisson_periods"}, {"mean_periods", 1.5}, {"period_us", 10000}};
  const nlohmann::json p = resolve_study(parse(j, ONESHOT_ENGINE_EXAMPLE_STUDY));
  const nlohmann::json& ca = p.at("links")[1].at("base").at("delay");
  EXPECT_TRUE(ca.at("max_us").is_null());
  EXPECT_FALSE(ca.contains("cap_us"));
  EXPECT_TRUE(p.at("buses")[0].at("messages")[1].at("jitter_us").is_null());
  // A lognormal leg: bounded by its cap only, which is reported.
  j["links"][1]["delay"] = {{"model", "lognormal"}, {"median_us", 300}, {"sigma", 0.5}, {"cap_us", 90000}};
  const nlohmann::json l = resolve_study(parse(j, ONESHOT_ENGINE_EXAMPLE_STUDY));
  EXPECT_EQ(l.at("links")[1].at("base").at("delay").at("cap_us").get<double>(), 90000);
}

TEST(StudyCheck, BusOverloadIsRefusedNamingTheBus) {
  nlohmann::json j = read_json(ONESHOT_ENGINE_EXAMPLE_STUDY);
  for (int k = 0; k < 3; ++k) {  // 4 streams of 270 µs every 1 ms: 108 %
    j["buses"][0]["background"].push_back({{"name", "x" + std::to_string(k)}, {"id", 300 + k}, {"payload_bytes", 8}, {"period_us", 1000}});
  }
  j["buses"][0]["background"][0]["period_us"] = 1000;
  try {
    static_cast<void>(resolve_study(parse(j, ONESHOT_ENGINE_EXAMPLE_STUDY)));
    ADD_FAILURE() << "accepted";
  } catch (const engine::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("field 'buses[0]'"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("over 100 %"), std::string::npos) << e.what();
  }
}

TEST(StudyCheck, UnstabilizablePlantIsRefusedNamingThePlant) {
  // The ncs plant with B = 0: no input reaches the double integrator.
  nlohmann::json p = read_json(std::string(ONESHOT_STUDY_EXAMPLES_DIR) + "/../../../lut_gen/plants/networked_board.json");
  p["B"] = {{0.0}, {0.0}};
  const std::string dir = test::made_dir("oneshot_study_check", "unstabilizable");
  std::ofstream(dir + "/plant.json") << p.dump();
  nlohmann::json j = read_json(kNcsExample);
  j["plant"] = {{"file", "plant.json"}};
  try {
    static_cast<void>(resolve_study(parse(j, dir + "/study.json")));
    ADD_FAILURE() << "accepted";
  } catch (const engine::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("field 'plant'"), std::string::npos) << e.what();
  }
}

/// A folder holding the delay trace the fuzz harness gives its inputs ("delays.csv").
std::string trace_dir() {
  // One folder per process, written once: ctest runs the tests of this file in parallel processes.
  static const std::string dir = [] {
    const std::string d = test::made_dir("oneshot_study_check", "traces");
    std::ofstream(d + "/delays.csv") << "delay_us\n500\n# a comment\n1500\n\n250\n";
    std::filesystem::copy_file(std::string(ONESHOT_STUDY_EXAMPLES_DIR) + "/../../../lut_gen/plants/networked_board.json",
                               d + "/networked_board.json", std::filesystem::copy_options::overwrite_existing);
    return d;
  }();
  return dir;
}

/// What `study check` prints for a delay model, against the model's own draws: the sample
/// mean within 5 standard errors of mean_ns(), every draw inside [lower_bound, upper_bound].
TEST(StudyCheck, DelayMeansAndBoundsMatchTheDraws) {
  const auto model = [](const char* text) {
    return engine::parse_delay_model(nlohmann::json::parse(text), "delay", trace_dir());
  };
  const std::vector<engine::DelayModel> models = {
      model(R"({"model": "constant", "delay_us": 1200})"),
      model(R"({"model": "uniform", "min_us": 500, "max_us": 4000, "resolution_us": 7})"),
      model(R"({"model": "poisson_periods", "mean_periods": 1.5, "period_us": 10000, "offset_us": 300})"),
      model(R"({"model": "lognormal", "median_us": 3000, "sigma": 0.6, "shift_us": 500})"),
      model(R"({"model": "pareto", "scale_us": 1000, "alpha": 4.5, "shift_us": 200})"),
      // Caps that bite: the mean is the clamped draw's (finite for a Pareto tail with α ≤ 1).
      model(R"({"model": "lognormal", "median_us": 3000, "sigma": 1.2, "shift_us": 500, "cap_us": 8000})"),
      model(R"({"model": "lognormal", "median_us": 3000, "sigma": 0, "shift_us": 500, "cap_us": 2000})"),
      model(R"({"model": "pareto", "scale_us": 200, "alpha": 1.0, "shift_us": 10, "cap_us": 50000})"),
      model(R"({"model": "pareto", "scale_us": 200, "alpha": 0.7, "cap_us": 20000})"),
      model(R"({"model": "pareto", "scale_us": 200, "alpha": 1.3, "cap_us": 150})"),
      model(R"({"model": "trace", "file": "delays.csv"})")};
  for (const engine::DelayModel& d : models) {
    engine::RandomStream rng(3, "delay-test");
    const std::size_t n = 200000;
    double sum = 0;
    double sum2 = 0;
    const auto ub = d.upper_bound();
    for (std::size_t k = 0; k < n; ++k) {
      bool clamped = false;
      const engine::Duration x = d.draw(rng, k, clamped);
      ASSERT_GE(x, d.lower_bound()) << d.describe();
      if (ub) {
        ASSERT_LE(x, *ub) << d.describe();
      }
      const double v = static_cast<double>(x.count());
      sum += v;
      sum2 += v * v;
    }
    const double mean = sum / static_cast<double>(n);
    const double se = std::sqrt(std::fmax(0.0, sum2 / static_cast<double>(n) - mean * mean) / static_cast<double>(n));
    EXPECT_NEAR(mean, d.mean_ns(), 5 * se + 1e-9 * d.mean_ns()) << d.describe();
  }
}

/// Every number of a resolution is finite (or null: an unbounded delay or response time).
void expect_finite(const nlohmann::json& j, const std::string& where) {
  if (j.is_number()) {
    EXPECT_TRUE(std::isfinite(j.get<double>())) << where;
  }
  if (j.is_structured()) {
    for (const auto& [k, v] : j.items()) expect_finite(v, where + "." + k);
  }
}

/// The fuzz harness's seed files (and any study file a fuzzer accepts): study check either
/// refuses naming a field or resolves to finite figures; the ncs mapping likewise.
TEST(StudyCheck, FuzzCorpusFilesResolveOrAreRefusedNamingAField) {
  std::size_t files = 0;
  std::size_t mapped = 0;
  for (const auto& entry : std::filesystem::directory_iterator(ONESHOT_STUDY_FUZZ_CORPUS)) {
    std::ifstream in(entry.path());
    std::stringstream text;
    text << in.rdbuf();
    engine::StudyFile f;
    try {
      f = engine::parse_study(text.str(), trace_dir() + "/" + entry.path().filename().string(), nullptr, trace_dir());
    } catch (const engine::InputError&) {
      continue;  // the parser refuses it
    }
    ++files;
    try {
      expect_finite(resolve_study(f), entry.path().filename().string());
    } catch (const engine::InputError& e) {
      EXPECT_NE(std::string(e.what()).find("field '"), std::string::npos) << e.what();
    }
    try {
      static_cast<void>(map_ncs_study(f));
      ++mapped;
    } catch (const engine::InputError& e) {
      EXPECT_NE(std::string(e.what()).find("field '"), std::string::npos) << e.what();
    }
  }
  EXPECT_GE(files, 4U);
  EXPECT_GE(mapped, 1U);  // the ncs seed maps onto the loop
}

/// Every shipped example (its relative plant, reference and CSV paths against its own folder)
/// parses, resolves to finite figures and maps onto the ncs loop: `study run` runs each.
TEST(StudyCheck, EveryShippedExampleResolvesAndMaps) {
  std::size_t files = 0;
  for (const auto& entry : std::filesystem::directory_iterator(ONESHOT_STUDY_EXAMPLES_DIR)) {
    if (entry.path().extension() != ".json") continue;
    std::ifstream in(entry.path());
    std::stringstream text;
    text << in.rdbuf();
    const std::string name = entry.path().filename().string();
    if (nlohmann::json::parse(text.str()).at("study") == "dropping") {  // the dropping loop (study_dropping_test.cpp)
      const engine::StudyFile f = engine::parse_study(text.str(), entry.path().string(), &dropping_schema(), ONESHOT_STUDY_EXAMPLES_DIR);
      expect_finite(resolve_study(f), name);
      EXPECT_NO_THROW(static_cast<void>(map_dropping_study(f))) << name;
      ++files;
      continue;
    }
    if (nlohmann::json::parse(text.str()).at("study") == "sod") {  // the sod study's run (study_sod_test.cpp)
      const engine::StudyFile f = engine::parse_study(text.str(), entry.path().string(), &sod_schema(), ONESHOT_STUDY_EXAMPLES_DIR);
      expect_finite(resolve_sod_study(f), name);
      EXPECT_NO_THROW(static_cast<void>(map_sod_study(f))) << name;
      ++files;
      continue;
    }
    if (nlohmann::json::parse(text.str()).at("study") == "oneshot") {  // the one-shot board (study_oneshot_file_test.cpp)
      const engine::StudyFile f = engine::parse_study(text.str(), entry.path().string(), &oneshot_schema(), ONESHOT_STUDY_EXAMPLES_DIR);
      expect_finite(resolve_study(f), name);
      EXPECT_NO_THROW(static_cast<void>(map_oneshot_study(f))) << name;
      ++files;
      continue;
    }
    if (nlohmann::json::parse(text.str()).at("study") == "petc") {  // the petc loop (study_petc_test.cpp)
      const engine::StudyFile f = engine::parse_study(text.str(), entry.path().string(), &petc_schema(), ONESHOT_STUDY_EXAMPLES_DIR);
      expect_finite(resolve_study(f), name);
      EXPECT_NO_THROW(static_cast<void>(map_petc_study(f))) << name;
      ++files;
      continue;
    }
    const engine::StudyFile f = engine::parse_study(text.str(), entry.path().string(), &ncs_schema(), ONESHOT_STUDY_EXAMPLES_DIR);
    expect_finite(resolve_study(f), name);
    EXPECT_NO_THROW(static_cast<void>(map_ncs_study(f))) << name;
    ++files;
  }
  EXPECT_GE(files, 10U);  // dropping, ncs, ncs_can, three on CPUs, sod_ge_oneshot, two_loops_can, two_loops_can_phase, mtm_file_oneshot
}

TEST(StudyCheck, CommandLine) {
  const std::string tmp = test::made_dir("oneshot_study_check", "cli") + "/check.json";
  test::CommandOptions to_file;
  to_file.stdout_path = tmp;
  const test::CommandResult ok = test::run_command({ONESHOT_SIM_PATH, "study", "check", kNcsExample, "--json", "-"}, to_file);
  ASSERT_EQ(ok.exit_code, 0) << ok.output;
  const nlohmann::json r = read_json(tmp);
  EXPECT_EQ(r.at("runs_with"), "ncs");
  ASSERT_EQ(r.at("approaches")[7].at("kind"), "S+");
  EXPECT_EQ(r.at("approaches")[7].at("per_scenario").size(), 10U);
  EXPECT_TRUE(r.at("runnable").get<bool>());
  // A file study run cannot run: the whole resolution (CAN bounds included), then one line
  // naming the field, and a non-zero exit.
  const test::CommandResult ex = test::run_command({ONESHOT_SIM_PATH, "study", "check", ONESHOT_ENGINE_EXAMPLE_STUDY});
  EXPECT_NE(ex.exit_code, 0);
  const nlohmann::json er = resolve_study(engine::load_study(ONESHOT_ENGINE_EXAMPLE_STUDY, nullptr));
  for (const nlohmann::json& m : er.at("buses")[0].at("messages")) {
    const std::string bound = "worst response " + m.at("worst_response_us").dump() + " us";
    EXPECT_NE(ex.output.find(bound), std::string::npos) << bound << "\n" << ex.output;
  }
  EXPECT_NE(ex.output.find("grid: "), std::string::npos) << ex.output;
  EXPECT_NE(ex.output.find("\ncannot run: field 'study': "), std::string::npos) << ex.output;
  EXPECT_EQ(ex.output.find("runs with"), std::string::npos) << ex.output;
  test::CommandOptions ex_file;
  ex_file.stdout_path = tmp;
  const test::CommandResult exj =
      test::run_command({ONESHOT_SIM_PATH, "study", "check", ONESHOT_ENGINE_EXAMPLE_STUDY, "--json", "-"}, ex_file);
  EXPECT_NE(exj.exit_code, 0);
  const nlohmann::json xr = read_json(tmp);
  EXPECT_FALSE(xr.at("runnable").get<bool>());
  EXPECT_EQ(xr.at("refusal").get<std::string>().rfind("field 'study': ", 0), 0U) << xr.at("refusal");
  EXPECT_EQ(xr.at("buses"), er.at("buses"));
  // Bad input: one line, non-zero exit, nothing written.
  nlohmann::json over = read_json(ONESHOT_ENGINE_EXAMPLE_STUDY);
  over["buses"][0]["background"][0]["period_us"] = 200;  // 270 µs every 200 µs
  const std::string dir = test::made_dir("oneshot_study_check", "cli_overload");
  std::ofstream(dir + "/study.json") << over.dump();
  const std::string over_json = dir + "/check.json";
  std::filesystem::remove(over_json);
  const test::CommandResult ov = test::run_command({ONESHOT_SIM_PATH, "study", "check", dir + "/study.json", "--json", over_json});
  EXPECT_NE(ov.exit_code, 0);
  EXPECT_NE(ov.output.find("field 'buses[0]'"), std::string::npos) << ov.output;
  EXPECT_EQ(std::count(ov.output.begin(), ov.output.end(), '\n'), 1) << ov.output;
  EXPECT_FALSE(std::filesystem::exists(over_json));
  // Refused: one line naming the field, non-zero exit, nothing written.
  const std::string out = test::fresh_dir("oneshot_study_check", "cli_refused");
  const test::CommandResult bad = test::run_command({ONESHOT_SIM_PATH, "study", "run", ONESHOT_ENGINE_EXAMPLE_STUDY, "--out", out});
  EXPECT_NE(bad.exit_code, 0);
  EXPECT_NE(bad.output.find("field 'study'"), std::string::npos) << bad.output;
  EXPECT_EQ(std::count(bad.output.begin(), bad.output.end(), '\n'), 1) << bad.output;
  EXPECT_FALSE(std::filesystem::exists(out));
}

}  // namespace
}  // namespace oneshot::study
