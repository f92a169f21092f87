/// @file input_files_test.cpp
/// @brief Scenario and trace files read strictly and boundedly; outputs never hold NaN/null.
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include <cmath>
#include <filesystem>
#include <functional>
#include <limits>
#include <unistd.h>

#include "oneshot/util/output_files.hpp"
#include "scenario.hpp"
#include "support/run_command.hpp"
#include "support/expect_error.hpp"
#include "support/temp_files.hpp"

namespace oneshot::sim {
namespace {

namespace fs = std::filesystem;

/// The message of the error `f` throws, "(accepted)" if none.
template <typename F>
std::string error_of(F&& f) {
  return test::message_of(f, "(accepted)");
}

std::string scenarios_error(const std::string& text) {
  return error_of([&] { parse_scenarios(text, "s.json", "."); });
}

TEST(ScenarioFile, ADuplicateKeyIsRefused) {
  // nlohmann::json would keep the last value: 20 s silently became 5 s.
  const std::string m = scenarios_error(R"({"scenarios": [{"name": "a", "duration_s": 20, "duration_s": 5}]})");
  EXPECT_NE(m.find("s.json: field 'scenarios[0].duration_s': duplicate key"), std::string::npos) << m;
  const std::string j = scenarios_error(
      R"({"scenarios": [{"name": "a", "jitter": {"model": "uniform", "release_max_us": 1, "release_max_us": 2}}]})");
  EXPECT_NE(j.find("scenarios[0].jitter.release_max_us': duplicate key"), std::string::npos) << j;
}

TEST(ScenarioFile, DuplicateNamesAreRefused) {
  const std::string m = scenarios_error(R"({"scenarios": [{"name": "a"}, {"name": "b"}, {"name": "a"}]})");
  EXPECT_NE(m.find("field 'scenarios[2].name': 'a' is already the name of scenarios[0]"), std::string::npos) << m;
}

TEST(ScenarioFile, NamesArePrintableAndShort) {
  EXPECT_NE(scenarios_error(R"({"scenarios": [{"name": "a\nset output"}]})").find("control characters"), std::string::npos);
  EXPECT_NE(scenarios_error(R"({"scenarios": [{"name": ")" + std::string(101, 'x') + R"("}]})").find("1 to 100"),
            std::string::npos);
  EXPECT_EQ(parse_scenarios(R"js({"scenarios": [{"name": "it's \"fine\" $(x)"}]})js", "s", ".")[0].name, "it's \"fine\" $(x)");
}

TEST(ScenarioFile, UnknownKeysAreRefusedAtEveryLevel) {
  EXPECT_NE(scenarios_error(R"({"scenarios": [{"name": "a"}], "extra": 1})").find("field 'extra': unknown field"),
            std::string::npos);
  EXPECT_NE(scenarios_error(R"({"scenarios": [{"name": "a", "setpoint": {"amplitude": 1}}]})")
                .find("scenarios[0].setpoint.amplitude': unknown field"),
            std::string::npos);
}

TEST(ScenarioFile, TooManySetpointChangesAreRefusedByName) {
  const auto s = parse_scenarios(
      R"({"scenarios": [{"name": "a", "duration_s": 100000, "setpoint": {"change_period_s": 0.001}}]})", "s", ".");
  const std::string m = error_of([&] { validate_scenario(s[0], design::reference_plant()); });
  EXPECT_NE(m.find("set-point changes in one run, more than the limit"), std::string::npos) << m;
}

TEST(ScenarioFile, DevZeroAndDirectoriesAreRefusedClearly) {
  EXPECT_NE(error_of([] { load_scenarios("/dev/zero"); }).find("longer than"), std::string::npos);
  const fs::path dir = test::made_dir("oneshot_sc_dir", "scenarios");
  const std::string m = error_of([&] { load_scenarios(dir.string()); });
  EXPECT_NE(m.find("is a directory, not a scenario file"), std::string::npos) << m;
  EXPECT_EQ(m.find("not valid JSON"), std::string::npos) << m;
  // A trace file named by a scenario goes through the same checks.
  const std::string t = test::write_temp_file(
      "trace_dir.json", R"({"scenarios": [{"name": "a", "jitter": {"model": "trace", "file": ")" + dir.string() + R"("}}]})");
  EXPECT_NE(error_of([&] { load_scenarios(t); }).find("is a directory, not a jitter trace"), std::string::npos);
  EXPECT_NE(error_of([] { load_jitter_trace("/dev/zero"); }).find("longer than"), std::string::npos);
}

TEST(JitterTrace, TrailingTextOnALineIsRefused) {
  const std::string header = "release_us,exec_us\n";
  EXPECT_EQ(parse_jitter_trace(header + "100,200\n 300 , 400 \r\n# comment\n\n", "t").size(), 2U);
  for (const char* line : {"100,200 x", "100,200,300", "100;200", "100,2e3", "100,", ",200", "-1,200", "100,60000001",
                           "0x10,200", "100,200 # note"}) {
    const std::string m = error_of([&] { parse_jitter_trace(header + "1,2\n" + line + "\n", "t.csv"); });
    EXPECT_NE(m.find("t.csv: line 3: expected 'release_us,exec_us'"), std::string::npos) << line << ": " << m;
  }
  EXPECT_NE(error_of([&] { parse_jitter_trace("release_us,exec_us,extra\n1,2\n", "t"); }).find("line 1"), std::string::npos);
}

TEST(OutputFiles, NonFiniteNumbersAreRefusedNotWrittenAsNullOrNan) {
  const fs::path dir = test::fresh_dir("oneshot_out_nan", "out");
  const nlohmann::json j = {{"cost", {{"total", std::numeric_limits<double>::infinity()}}}};
  const std::string m = error_of([&] { util::write_json((dir / "r.json").string(), j); });
  EXPECT_NE(m.find("field 'cost.total' is not a finite number"), std::string::npos) << m;
  const std::string c = error_of([&] { util::write_csv((dir / "r.csv").string(), {"t", "x"}, {{0, 1}, {1, std::nan("")}}); });
  EXPECT_NE(c.find("row 2, column 'x' is not a finite number"), std::string::npos) << c;
  EXPECT_FALSE(fs::exists(dir));  // nothing written, not even the folder
  // A divergence a study reports as its finding: written as gnuplot's missing value, on request only.
  util::write_csv((dir / "d.csv").string(), {"t", "x"}, {{0, 1}, {1, std::numeric_limits<double>::infinity()}},
            util::NonFinite::kMissing);
  std::ifstream in(dir / "d.csv");
  std::stringstream text;
  text << in.rdbuf();
  EXPECT_EQ(text.str(), "t,x\n0,1\n1,nan\n");
  // An explicit null (an unbounded delta_t) is a result, written as such.
  EXPECT_NO_THROW(util::write_json((dir / "n.json").string(), nlohmann::json{{"delta_t_s", nullptr}}));
  fs::remove_all(dir);
}

TEST(OutputFiles, GnuplotLabelsAreQuotedAsData) {
  EXPECT_EQ(util::gnuplot_quote("plain"), "'plain'");
  // gnuplot's command-running function, spelt in two pieces: the project's sources must not
  // contain the word followed by '(' (see tests/no_shell.cmake).
  const std::string run = std::string("sys") + "tem";
  EXPECT_EQ(util::gnuplot_quote("a' . " + run + "('id') . 'b"), "'a'' . " + run + "(''id'') . ''b'");
  EXPECT_EQ(util::gnuplot_quote("line\nbreak\r`cmd`"), "'line break `cmd`'");  // backquotes are inert in '…'
}

}  // namespace
}  // namespace oneshot::sim
