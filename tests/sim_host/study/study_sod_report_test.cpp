/// @file study_sod_report_test.cpp
/// @brief `study report` and `study bench` of a "study": "sod" file (sim_host/study/study_sod_report.cpp):
///        the report's files and sections, its traced runs against the sweep's, and the bench's
///        events against the runs' packets.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

#include "support/run_command.hpp"
#include "support/temp_files.hpp"

namespace oneshot::study {
namespace {

const std::string kSodReportExample = std::string(ONESHOT_STUDY_EXAMPLES_DIR) + "/sod.json";

TEST(StudySodReport, WritesTheReportWithTracesOfTheSweepsRuns) {
  const std::string dir = test::made_dir("oneshot_study_sod_report", "report");
  const test::CommandResult r = test::run_command(
      {ONESHOT_SIM_PATH, "study", "report", kSodReportExample, dir + "/out", "--seeds", "2", "--threads", "2", "--no-plots", "--trace", "msod,periodic"});
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const nlohmann::json j = nlohmann::json::parse(test::read_file(dir + "/out/report.json"));
  EXPECT_EQ(j.at("seeds"), 2);
  ASSERT_EQ(j.at("traces").size(), 2U);
  for (const char* a : {"msod", "periodic"}) {
    EXPECT_TRUE(j.at("traces").at(a).at("same_cost_as_sweep").get<bool>()) << a;
    for (const auto& f : j.at("traces").at(a).at("files")) EXPECT_TRUE(std::filesystem::exists(dir + "/out/" + f.get<std::string>())) << f;
  }
  EXPECT_TRUE(std::filesystem::exists(dir + "/out/table_summary.csv"));
  EXPECT_FALSE(std::filesystem::exists(dir + "/out/table.png"));  // --no-plots
  const std::string md = test::read_file(dir + "/out/report.md");
  for (const char* section : {"### Configuration", "### Estimation error", "### Links", "### Traces", "dt design msod on xi=0.05",
                              "over 2 seeds", "4 approaches x 4 scenarios x 2 seeds"})
    EXPECT_NE(md.find(section), std::string::npos) << section;
}

TEST(StudySodReport, BenchCountsOneEventPerDeliveryBesideTheSteps) {
  // A run's kernel events: per step the plant, the sample and the estimator (the same for every
  // approach at one N), plus one delivery per packet that arrived. So events - delivered is the
  // same for every approach (the sweeps' seeds are the same).
  const std::string dir = test::made_dir("oneshot_study_sod_report", "bench");
  test::CommandOptions to_file;
  to_file.stdout_path = dir + "/bench.json";
  const test::CommandResult b = test::run_command({ONESHOT_SIM_PATH, "study", "bench", kSodReportExample, "--seeds", "2", "--threads", "2",
                                                   "--json", "-"}, to_file);
  ASSERT_EQ(b.exit_code, 0) << b.output;
  const test::CommandResult r = test::run_command({ONESHOT_SIM_PATH, "study", "run", kSodReportExample, "--seeds", "2", "--threads", "2",
                                                   "--out", dir + "/run", "--json", dir + "/run.json"});
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const nlohmann::json bench = nlohmann::json::parse(test::read_file(dir + "/bench.json"));
  const nlohmann::json run = nlohmann::json::parse(test::read_file(dir + "/run.json"));
  double base = -1;
  for (const char* a : {"sod-held", "sod-kf", "msod", "periodic"}) {
    const double delivered = run.at("links").at(a).at("node1").at("delivered").get<double>() +
                             run.at("links").at(a).at("node2").at("delivered").get<double>();
    const double rest = bench.at("per_approach").at(a).at("events").get<double>() - delivered;
    if (base < 0) base = rest;
    EXPECT_EQ(rest, base) << a;
    // The bench's mean cost is the run's (the same runs, summed in another order: 1e-14 relative).
    const double mean = run.at("approaches").at(a).at("cost_mean").get<double>();
    EXPECT_NEAR(bench.at("per_approach").at(a).at("cost_mean").get<double>(), mean, 1e-14 * mean) << a;
  }
  EXPECT_GE(base, 3.0 * 8 * 5000);  // 8 runs per approach: at least the plant, the sample and the estimator per step
  EXPECT_GT(bench.at("events_per_cpu_s").get<double>(), 0.0);
}

}  // namespace
}  // namespace oneshot::study
