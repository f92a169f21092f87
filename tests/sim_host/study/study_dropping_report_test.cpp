/// @file study_dropping_report_test.cpp
/// @brief `study report` and `study bench` of a "study": "dropping" file
///        (sim_host/study/study_dropping_report.cpp, study_bench.cpp): the report's figures are
///        `study run --json`'s on the same seeds, the same bytes on 1 and 2 threads, the traced run
///        is the sweep's, refusals name the field and write nothing; the bench's events and rates.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "support/run_command.hpp"
#include "support/temp_files.hpp"

namespace oneshot::study {
namespace {

const std::string kDropReportExample = std::string(ONESHOT_STUDY_EXAMPLES_DIR) + "/dropping.json";

/// `v` as the report prints it with `format` ("—" for null: a diverged mean).
std::string drop_printed(const nlohmann::json& v, const char* format) {
  if (v.is_null()) return "—";
  char b[48];
  std::snprintf(b, sizeof b, format, v.get<double>());
  return b;
}

TEST(StudyDroppingReport, HoldsTheFiguresOfStudyRunAndTheSameBytesOnOneAndTwoThreads) {
  const std::string dir = test::made_dir("oneshot_study_dropping_report", "figures");
  const test::CommandResult run = test::run_command({ONESHOT_SIM_PATH, "study", "run", kDropReportExample, "--seeds", "6", "--threads",
                                                     "2", "--out", dir + "/run", "--json", dir + "/run.json"});
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const auto report = [&](const std::string& out, const char* threads, bool plots) {
    std::vector<std::string> argv{ONESHOT_SIM_PATH, "study", "report", kDropReportExample, out, "--seeds", "6", "--threads", threads};
    if (!plots) argv.emplace_back("--no-plots");
    const test::CommandResult r = test::run_command(argv);
    EXPECT_EQ(r.exit_code, 0) << r.output;
  };
  report(dir + "/t1", "1", false);
  report(dir + "/t2", "2", false);
  const nlohmann::json j = nlohmann::json::parse(test::read_file(dir + "/run.json"));
  const nlohmann::json rj = nlohmann::json::parse(test::read_file(dir + "/t1/report.json"));
  // report.json: the run's summary, value for value (the same runs, the same sums).
  for (const char* key : {"approaches", "paired_differences", "per_scenario", "links", "order_by_mean_cost", "markdown", "settings"})
    EXPECT_EQ(rj.at(key), j.at(key)) << key;
  // report.md: the run's table, its order, every paired difference and every link counter as printed.
  const std::string md = test::read_file(dir + "/t1/report.md");
  EXPECT_NE(md.find("`dropping.json`"), std::string::npos) << md;
  EXPECT_NE(md.find("grid: 4 approaches x 3 scenarios x 6 seeds = 72 runs"), std::string::npos) << md;
  EXPECT_NE(md.find(j.at("markdown").get<std::string>()), std::string::npos) << md;
  EXPECT_NE(md.find("Order by mean cost (measured): " + j.at("order_text").get<std::string>()), std::string::npos) << md;
  EXPECT_NE(md.find("lambda_c in ["), std::string::npos) << md;  // the design as study check gives it
  for (const auto& [pair, d] : j.at("paired_differences").items()) {
    const std::string row = "| " + pair + " | " + drop_printed(d.at("mean"), "%.6g") + " | ± " + drop_printed(d.at("ci95"), "%.3g") + " |";
    EXPECT_NE(md.find(row), std::string::npos) << row << "\n" << md;
  }
  for (const auto& [name, l] : j.at("links").items()) {
    const nlohmann::json& c = l.at("sc");
    std::string row = "| " + name + " | sc |";
    for (const char* k : {"sent", "delivered", "lost", "late", "refused"}) row += " " + drop_printed(c.at(k), "%.0f") + " |";
    EXPECT_NE(md.find(row), std::string::npos) << row << "\n" << md;
  }
  // The estimator's consistency ratio E|x - xhat|^2 / E tr P of the buffered filter, from the run's figures.
  const nlohmann::json& b = j.at("approaches").at("buffered");
  const std::string ratio = drop_printed(b.at("err_mean").get<double>() / b.at("trace_p_mean").get<double>(), "%.4f");
  EXPECT_NE(md.find("| buffered | " + drop_printed(b.at("err_mean"), "%.6g") + " | " + drop_printed(b.at("trace_p_mean"), "%.6g") +
                    " | " + ratio + " |"),
            std::string::npos)
      << md;
  // The same bytes on 1 and 2 threads: every file the report writes.
  std::size_t files = 0;
  for (const auto& f : std::filesystem::directory_iterator(dir + "/t1")) {
    const std::string name = f.path().filename().string();
    EXPECT_EQ(test::read_file(f.path().string()), test::read_file(dir + "/t2/" + name)) << name;
    ++files;
  }
  EXPECT_EQ(files, 2U + 2U + 4U);  // report.md, report.json; runs.csv, table_summary.csv; a trace per approach
  // Each traced run is the sweep's run of scenario 0, seed 1: the same cost, bit for bit; one row per step.
  ASSERT_EQ(rj.at("traces").size(), 4U);
  for (const auto& [name, t] : rj.at("traces").items()) {
    EXPECT_TRUE(t.at("same_cost_as_sweep").get<bool>()) << name;
    const std::string csv = test::read_file(dir + "/t1/" + t.at("files")[0].get<std::string>());
    EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 1 + 1000) << name;  // header + 10 s / 10 ms steps
    EXPECT_EQ(csv.rfind("k,t_s,r,y,cx,cxhat,u,trace_p,err\n", 0), 0U) << name;
  }
  // With plots: the cost bars and a plot per trace, linked from the report.
  report(dir + "/plots", "2", true);
  const std::string pmd = test::read_file(dir + "/plots/report.md");
  EXPECT_NE(pmd.find("](table.png)"), std::string::npos) << pmd;
  EXPECT_GT(std::filesystem::file_size(dir + "/plots/table.png"), 0U);
  EXPECT_GT(std::filesystem::file_size(dir + "/plots/trace_1_buffered.png"), 0U);
}

TEST(StudyDroppingReport, RefusalsNameTheFieldAndWriteNothing) {
  const std::string dir = test::made_dir("oneshot_study_dropping_report", "refusals");
  nlohmann::json bad = nlohmann::json::parse(test::read_file(kDropReportExample));
  bad["approaches"][0]["kind"] = "smith";
  bad["plant"]["file"] = std::string(ONESHOT_STUDY_EXAMPLES_DIR) + "/" + bad["plant"]["file"].get<std::string>();
  const std::string bad_file = dir + "/bad.json";
  std::ofstream(bad_file) << bad.dump();
  const std::vector<std::pair<std::vector<std::string>, std::string>> cases = {
      {{kDropReportExample, "--trace", "kalman"}, "field '--trace'"},
      {{kDropReportExample, "--trace", "buffered,buffered"}, "field '--trace'"},
      {{kDropReportExample, "--max-duration", "1"}, "field '--max-duration'"},
      {{bad_file}, "field 'approaches[0].kind'"},
  };
  for (std::size_t i = 0; i < cases.size(); ++i) {
    const std::string out = dir + "/out" + std::to_string(i);
    std::vector<std::string> argv{ONESHOT_SIM_PATH, "study", "report", cases[i].first[0], out, "--seeds", "2"};
    argv.insert(argv.end(), cases[i].first.begin() + 1, cases[i].first.end());
    const test::CommandResult r = test::run_command(argv);
    EXPECT_NE(r.exit_code, 0) << cases[i].second;
    EXPECT_NE(r.output.find(cases[i].second), std::string::npos) << r.output;
    EXPECT_FALSE(std::filesystem::exists(out)) << out;  // nothing written, not even the folder
  }
  const test::CommandResult bench = test::run_command({ONESHOT_SIM_PATH, "study", "bench", kDropReportExample, "--max-duration", "1"});
  EXPECT_NE(bench.exit_code, 0);
  EXPECT_NE(bench.output.find("field '--max-duration'"), std::string::npos) << bench.output;
}

TEST(StudyDroppingBench, CountsEveryStepsEventsAndGivesTheCostsOfStudyRun) {
  const std::string dir = test::made_dir("oneshot_study_dropping_report", "bench");
  test::CommandOptions to_file;
  to_file.stdout_path = dir + "/bench.json";
  const test::CommandResult b =
      test::run_command({ONESHOT_SIM_PATH, "study", "bench", kDropReportExample, "--seeds", "2", "--threads", "2", "--json", "-"}, to_file);
  ASSERT_EQ(b.exit_code, 0) << b.output;
  const test::CommandResult run = test::run_command({ONESHOT_SIM_PATH, "study", "run", kDropReportExample, "--seeds", "2", "--threads",
                                                     "1", "--out", dir + "/run", "--json", dir + "/run.json"});
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const nlohmann::json j = nlohmann::json::parse(test::read_file(dir + "/bench.json"));
  const nlohmann::json r = nlohmann::json::parse(test::read_file(dir + "/run.json"));
  EXPECT_EQ(j.at("runs").get<std::size_t>(), 4U * 3U * 2U);
  EXPECT_EQ(j.at("threads").get<unsigned>(), 2U);
  // Every run: 1000 steps, each a sample and a computation at least (plus the plant's steps and the deliveries).
  EXPECT_GE(j.at("events").get<double>(), 2.0 * 1000 * 24);
  EXPECT_EQ(j.at("simulated_s").get<double>(), 10.0 * 24);
  for (const char* rate : {"events_per_s", "events_per_s_per_thread", "events_per_cpu_s", "wall_s", "cpu_s"})
    EXPECT_GT(j.at(rate).get<double>(), 0.0) << rate;
  // Per approach the mean cost over its runs is study run's cost_mean (the mean over seeds of the
  // scenario means: the same terms summed in another order). Measured: 0 and 2.2e-16 relative
  // (buffered, buffered-bernoulli); 1e-15 allowed.
  for (const auto& [name, a] : r.at("approaches").items()) {
    const nlohmann::json& mine = j.at("per_approach").at(name).at("cost_mean");
    ASSERT_EQ(mine.is_null(), a.at("cost_mean").is_null()) << name;
    if (!mine.is_null()) {
      EXPECT_NEAR(mine.get<double>(), a.at("cost_mean").get<double>(), 1e-15 * a.at("cost_mean").get<double>()) << name;
    }
    EXPECT_GT(j.at("per_approach").at(name).at("events").get<double>(), 0.0) << name;
  }
}

}  // namespace
}  // namespace oneshot::study
