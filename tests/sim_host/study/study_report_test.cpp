/// @file study_report_test.cpp
/// @brief `oneshot-sim study report FILE OUTDIR`: on the shipped example the report names every
///        approach with the cost, interval and link counters `study run --json` gives for the
///        same seeds, and links a plot that exists; bad input writes nothing. `--max-duration`
///        (study run, study report, the fuzz harness) cuts every scenario's simulated time.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "ncs_loop.hpp"
#include "oneshot/engine/study_file.hpp"
#include "study_dropping_runner.hpp"
#include "study_ncs_runner.hpp"
#include "study_ncs_sweep.hpp"
#include "study_oneshot_study.hpp"
#include "study_petc_study.hpp"
#include "study_sod_runner.hpp"
#include "support/run_command.hpp"
#include "support/temp_files.hpp"

namespace oneshot::study {
namespace {

const std::string kExample = std::string(ONESHOT_STUDY_EXAMPLES_DIR) + "/ncs.json";

nlohmann::json read_report_json(const std::string& path) { return nlohmann::json::parse(test::read_file(path)); }

/// The cells of a markdown table row "| a | b | … |" (trimmed), empty when `line` is not one.
std::vector<std::string> cells(const std::string& line) {
  std::vector<std::string> out;
  if (line.size() < 2 || line.front() != '|' || line.back() != '|') return out;
  std::stringstream s(line.substr(1, line.size() - 2));
  for (std::string c; std::getline(s, c, '|');) {
    const auto b = c.find_first_not_of(' ');
    const auto e = c.find_last_not_of(' ');
    out.push_back(b == std::string::npos ? "" : c.substr(b, e - b + 1));
  }
  return out;
}

/// The rows of the markdown table that follows the line starting with `header` in `md`, by
/// their first cell (joined with the second when `key_cells` is 2).
std::map<std::string, std::vector<std::string>> table_after(const std::string& md, const std::string& header, int key_cells) {
  std::map<std::string, std::vector<std::string>> rows;
  std::stringstream s(md);
  bool in = false;
  for (std::string line; std::getline(s, line);) {
    if (!in) {  // the rows start after the header line
      in = line.rfind(header, 0) == 0;
      continue;
    }
    const std::vector<std::string> c = cells(line);
    if (c.empty()) {
      if (!rows.empty()) break;
      continue;
    }
    if (c[0].rfind("---", 0) == 0 || static_cast<int>(c.size()) < key_cells) continue;
    rows[key_cells == 2 ? c[0] + "/" + c[1] : c[0]] = c;
  }
  return rows;
}

/// "± 0.0123" → 0.0123.
double number(const std::string& cell) {
  const auto p = cell.find_first_of("-0123456789");
  return p == std::string::npos ? std::nan("") : std::strtod(cell.c_str() + p, nullptr);
}

TEST(StudyReport, NamesEveryApproachWithTheCostsOfStudyRun) {
  const std::string run_dir = test::fresh_dir("oneshot_study_report", "run");
  const std::string run_json = run_dir + "/run.json";
  const test::CommandResult run = test::run_command({ONESHOT_SIM_PATH, "study", "run", kExample, "--seeds", "2", "--threads",
                                                     "2", "--no-plots", "--out", run_dir, "--json", run_json});
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const std::string out = test::fresh_dir("oneshot_study_report", "report");
  const test::CommandResult rep =
      test::run_command({ONESHOT_SIM_PATH, "study", "report", kExample, out, "--seeds", "2", "--threads", "2", "--trace", "AK"});
  ASSERT_EQ(rep.exit_code, 0) << rep.output;
  const nlohmann::json j = read_report_json(run_json);
  const std::string md = test::read_file(out + "/report.md");
  ASSERT_FALSE(md.empty());
  EXPECT_NE(md.find("`ncs.json`"), std::string::npos) << md;
  const std::size_t approaches = j.at("approaches").size();
  const std::size_t scenarios = j.at("scenarios").size();
  const std::string grid = "grid: " + std::to_string(approaches) + " approaches x " + std::to_string(scenarios) +
                           " scenarios x 2 seeds = " + std::to_string(approaches * scenarios * 2) + " runs";
  EXPECT_NE(md.find(grid), std::string::npos) << md;  // what ran
  EXPECT_NE(md.find("Simulated time per run:"), std::string::npos) << md;
  EXPECT_EQ(md.find("capped by --max-duration"), std::string::npos) << md;
  // The cost table: every approach, mean and interval as study run's to the 6 decimals printed.
  const auto costs = table_after(md, "| approach | description | mean cost J", 1);
  const auto links = table_after(md, "| approach | link |", 2);
  ASSERT_EQ(j.at("approaches").size(), 9U);
  for (const auto& [name, a] : j.at("approaches").items()) {
    ASSERT_EQ(costs.count(name), 1U) << name << "\n" << md;
    const std::vector<std::string>& row = costs.at(name);
    ASSERT_GE(row.size(), 5U);
    EXPECT_NEAR(number(row[2]), a.at("cost_mean").get<double>(), 5.1e-7) << name;
    EXPECT_NEAR(number(row[3]), a.at("cost_ci95").get<double>(), 5.1e-7) << name;
    EXPECT_NEAR(number(row[4]), a.at("ratio_to_I").get<double>(), 5.1e-5) << name;
    for (const auto& [link, counters] : j.at("links").at(name).items()) {
      ASSERT_EQ(links.count(name + "/" + link), 1U) << name << " " << link << "\n" << md;
      const std::vector<std::string>& l = links.at(name + "/" + link);
      ASSERT_EQ(l.size(), 2 + std::size(kLinkCounters));
      for (std::size_t c = 0; c < std::size(kLinkCounters); ++c)
        EXPECT_EQ(number(l[2 + c]), counters.at(kLinkCounters[c]).get<double>()) << name << " " << link << " " << kLinkCounters[c];
    }
  }
  // Every paired difference, with the run's figures.
  const auto pairs = table_after(md, "| pair | mean |", 1);
  EXPECT_EQ(pairs.size(), j.at("paired_differences").size());
  for (const auto& [pair, d] : j.at("paired_differences").items()) {
    ASSERT_EQ(pairs.count(pair), 1U) << pair;
    EXPECT_NEAR(number(pairs.at(pair)[1]), d.at("mean").get<double>(), 5.1e-7) << pair;
    EXPECT_NEAR(number(pairs.at(pair)[2]), d.at("ci95").get<double>(), 5.1e-7) << pair;
  }
  // report.json holds the run's figures, bit for bit (same seeds, same runs).
  const nlohmann::json rj = read_report_json(out + "/report.json");
  for (const auto& [name, a] : j.at("approaches").items())
    EXPECT_EQ(rj.at("approaches").at(name).at("cost_mean").get<double>(), a.at("cost_mean").get<double>()) << name;
  // The plot the report links is there.
  const std::string link = "](table.png)";
  ASSERT_NE(md.find(link), std::string::npos) << md;
  EXPECT_GT(std::filesystem::file_size(out + "/table.png"), 0U);
}

TEST(StudyReport, BadInputWritesNothing) {
  nlohmann::json bad = read_report_json(kExample);
  bad["scenarios"][0]["params"]["amplitude_volts"] = 1000;  // range [0, 100]
  bad["plant"]["file"] = std::string(ONESHOT_STUDY_EXAMPLES_DIR) + "/" + bad["plant"]["file"].get<std::string>();
  const std::string dir = test::made_dir("oneshot_study_report", "bad");
  std::ofstream(dir + "/study.json") << bad.dump();
  const std::vector<std::pair<std::vector<std::string>, std::string>> cases = {
      {{dir + "/study.json"}, "field 'scenarios[0].params.amplitude_volts'"},
      {{ONESHOT_ENGINE_EXAMPLE_STUDY}, "field 'study'"},                     // a file the loop cannot run
      {{kExample, "--max-duration", "0.01"}, "field '--max-duration'"},  // below h = 50 ms
      {{kExample, "--trace", "AK,XX"}, "field '--trace'"},              // no such approach
      {{kExample, "--trace", "AK,AK"}, "field '--trace'"},              // twice
      {{kExample, "--trace", ""}, "field '--trace'"}};
  for (const auto& [args, field] : cases) {
    const std::string out = test::fresh_dir("oneshot_study_report", "bad_out");
    std::vector<std::string> argv = {ONESHOT_SIM_PATH, "study", "report", args[0], out};
    argv.insert(argv.end(), args.begin() + 1, args.end());
    const test::CommandResult r = test::run_command(argv);
    EXPECT_NE(r.exit_code, 0) << args[0];
    EXPECT_NE(r.output.find(field), std::string::npos) << r.output;
    EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
    EXPECT_FALSE(std::filesystem::exists(out)) << args[0];
  }
}

TEST(StudyReport, MaxDurationCutsEveryScenario) {
  const NcsStudy file = map_ncs_study(engine::load_study(kExample, &ncs_schema()));
  NcsStudy capped = file;
  cap_duration(capped, 2.5, "--max-duration");  // past every scenario's first set-point switch (T_r/2 <= 2 s)
  NcsStudy cut = file;  // the same scenarios, shortened by hand
  for (ncs::Scenario& x : cut.scenarios) x.duration_s = 2.5;
  capped.scenarios.resize(2);
  cut.scenarios.resize(2);
  const engine::SweepResults a = run_ncs_sweep(capped, 2, 2, engine::Shard{});
  const engine::SweepResults b = run_ncs_sweep(cut, 2, 2, engine::Shard{});
  EXPECT_EQ(a.values, b.values);
  EXPECT_EQ(a.spec.to_json(), b.spec.to_json());
  NcsStudy longer = file;  // a cap above a scenario's duration leaves it
  cap_duration(longer, 1000, "--max-duration");
  for (std::size_t i = 0; i < file.scenarios.size(); ++i) EXPECT_EQ(longer.scenarios[i].duration_s, file.scenarios[i].duration_s);
  NcsStudy shorter = file;
  // Below h, or before a scenario's first set-point switch (I would cost 0: no ratio to it).
  for (double bad : {0.049, 0.0, -1.0, std::nan(""), 1.5}) {
    try {
      cap_duration(shorter, bad, "--max-duration");
      ADD_FAILURE() << bad << " accepted";
    } catch (const engine::InputError& e) {
      EXPECT_NE(std::string(e.what()).find("field '--max-duration'"), std::string::npos) << e.what();
    }
  }
  // From the command line: the run's scenarios say the simulated time they ran.
  const std::string out = test::fresh_dir("oneshot_study_report", "capped");
  const test::CommandResult r = test::run_command(
      {ONESHOT_SIM_PATH, "study", "run", kExample, "--seeds", "2", "--max-duration", "2.5", "--no-plots", "--out", out, "--json", out + "/run.json"});
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const nlohmann::json capped_run = read_report_json(out + "/run.json");  // kept alive: the loop reads inside it
  for (const auto& x : capped_run.at("scenarios")) EXPECT_EQ(x.at("duration_s").get<double>(), 2.5);
  // The report says its runs were cut; an explicit 0 is a cap below one period, refused.
  const std::string rep = test::fresh_dir("oneshot_study_report", "capped_report");
  const test::CommandResult rr = test::run_command(
      {ONESHOT_SIM_PATH, "study", "report", kExample, rep, "--seeds", "2", "--max-duration", "2.5", "--no-plots"});
  ASSERT_EQ(rr.exit_code, 0) << rr.output;
  EXPECT_NE(test::read_file(rep + "/report.md").find("(capped by --max-duration 2.5)"), std::string::npos);
  const std::string zero = test::fresh_dir("oneshot_study_report", "zero_cap");
  const test::CommandResult z = test::run_command(
      {ONESHOT_SIM_PATH, "study", "run", kExample, "--seeds", "2", "--max-duration", "0", "--no-plots", "--out", zero});
  EXPECT_NE(z.exit_code, 0);
  EXPECT_NE(z.output.find("field '--max-duration'"), std::string::npos) << z.output;
  EXPECT_FALSE(std::filesystem::exists(zero));
}

TEST(StudyReport, FuzzRunCorpusFilesRunWithinTheHarnessBound) {
  // The seeds of tests/fuzz/fuzz_study_run.cpp run, not refused: parsed in a folder that holds
  // what the harness's holds, ncs files cut at the harness's 0.3 s, the other studies' seeds
  // (within the harness's cuts but oneshot's 1 s) run whole on one seed (the run limits and
  // oracles are the harness's own; here: every figure finite).
  const std::string dir = test::made_dir("oneshot_study_report", "fuzz_corpus");
  for (const char* plant : {"networked_board.json", "sinopoli_dropping.json", "send_on_delta_oscillator.json", "hdd_numre.json",
                            "reference_board.json"})
    std::filesystem::copy_file(std::string(ONESHOT_STUDY_EXAMPLES_DIR) + "/../../../lut_gen/plants/" + plant, dir + "/" + plant);
  std::ofstream(dir + "/delays.csv") << "delay_us\n500\n# a comment\n1500\n\n250\n";
  std::size_t files = 0;
  std::map<std::string, std::size_t> other;  // files per study other than ncs
  for (const auto& f : std::filesystem::directory_iterator(std::string(ONESHOT_STUDY_FUZZ_CORPUS) + "/../study_run")) {
    ++files;
    const std::string text = test::read_file(f.path().string());
    const std::string study = engine::parse_study(text, dir + "/fuzz.json", nullptr, dir).study;
    if (study != "ncs") {
      ++other[study];
      const auto parse = [&](const engine::StudySchema& schema) { return engine::parse_study(text, dir + "/fuzz.json", &schema, dir); };
      engine::SweepResults r;
      if (study == "dropping") r = run_dropping_sweep(*map_dropping_study(parse(dropping_schema())), 1, 1, engine::Shard{});
      if (study == "sod") r = run_sod_sweep(*map_sod_study(parse(sod_schema())), 1, 1, engine::Shard{});
      if (study == "petc") r = run_petc_sweep(*map_petc_study(parse(petc_schema())), 1, 1, engine::Shard{});
      if (study == "oneshot") r = run_oneshot_sweep(*map_oneshot_study(parse(oneshot_schema())), 1, 1, engine::Shard{});
      EXPECT_TRUE(r.complete() && r.spec.runs() > 0) << f.path();
      for (std::size_t a = 0; a < r.spec.approaches.size(); ++a)
        for (std::size_t x = 0; x < r.spec.scenarios.size(); ++x)
          for (std::size_t m = 0; m < r.spec.metrics.size(); ++m)  // dropping's gamma: the buffered filter's only (NaN otherwise)
            if (study != "dropping" || r.spec.metrics[m] != "gamma") {
              EXPECT_TRUE(std::isfinite(r.at(a, x, 0, m))) << f.path() << " " << r.spec.metrics[m];
            }
      continue;
    }
    NcsStudy s = map_ncs_study(engine::parse_study(text, dir + "/fuzz.json", &ncs_schema(), dir));
    cap_duration(s, 0.3, "--max-duration");
    const engine::SweepResults r = run_ncs_sweep(s, 1, 1, engine::Shard{});
    for (double v : r.values) EXPECT_TRUE(std::isfinite(v)) << f.path();
  }
  EXPECT_GE(files, 3U);
  for (const char* study : {"dropping", "sod", "petc", "oneshot"}) EXPECT_GE(other[study], 1U) << study;
}

/// The rows of a CSV file (header included), split at commas (an empty field stays empty).
std::vector<std::vector<std::string>> csv_rows(const std::string& path) {
  std::vector<std::vector<std::string>> rows;
  std::stringstream in(test::read_file(path));
  for (std::string line; std::getline(in, line);) {
    std::vector<std::string>& row = rows.emplace_back();
    std::stringstream l(line);
    for (std::string c; std::getline(l, c, ',');) row.push_back(c);
    if (!line.empty() && line.back() == ',') row.emplace_back();
  }
  return rows;
}

TEST(StudyReport, TracingARunLeavesItsCostBitForBit) {
  // Every approach of the three shipped examples (links with loss, CAN legs, the one-shot
  // loops) on the first scenario and seed, cut at 3 s: traced and message-logged as `study
  // report --trace` runs it, and plain as the sweep runs it.
  for (const char* f : {"ncs.json", "ncs_can.json", "sod_ge_oneshot.json"}) {
    NcsStudy s = map_ncs_study(engine::load_study(std::string(ONESHOT_STUDY_EXAMPLES_DIR) + "/" + f, &ncs_schema()));
    cap_duration(s, 3, "--max-duration");
    ncs::RunOptions traced;
    traced.trace_step_s = 1e-3;
    traced.record_messages = true;
    for (ncs::Approach a : s.approaches) {
      const ncs::RunResult plain = ncs::run(*s.ctx, a, s.scenarios[0], s.first_seed, ncs::RunOptions{});
      const ncs::RunResult t = ncs::run(*s.ctx, a, s.scenarios[0], s.first_seed, traced);
      EXPECT_EQ(t.cost, plain.cost) << f << " " << ncs::name(a);
      EXPECT_EQ(t.commands, plain.commands) << f << " " << ncs::name(a);
      EXPECT_EQ(t.events, plain.events) << f << " " << ncs::name(a);
      EXPECT_TRUE(plain.messages.empty());
      EXPECT_EQ(t.truth.size(), 3001U) << f << " " << ncs::name(a);  // 0, 1 ms, ..., 3 s
      EXPECT_GT(t.events, 0U);
    }
  }
}

TEST(StudyReport, TracesHaveTheirColumnsAndTheRunsMessages) {
  // The one-shot example: its leg sc loses messages (Gilbert-Elliott), OSK has an estimator, I none.
  const std::string file = std::string(ONESHOT_STUDY_EXAMPLES_DIR) + "/sod_ge_oneshot.json";
  const std::string out = test::fresh_dir("oneshot_study_report", "traces");
  const test::CommandResult r = test::run_command({ONESHOT_SIM_PATH, "study", "report", file, out, "--seeds", "2", "--threads", "2",
                                                   "--max-duration", "3", "--trace", "OSK,I"});
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const nlohmann::json rep = read_report_json(out + "/report.json");
  ASSERT_EQ(rep.at("traces").size(), 2U);
  NcsStudy s = map_ncs_study(engine::load_study(file, &ncs_schema()));
  cap_duration(s, 3, "--max-duration");
  const std::string md = test::read_file(out + "/report.md");
  EXPECT_NE(md.find("### Traces"), std::string::npos);
  for (ncs::Approach a : {ncs::Approach::kOSK, ncs::Approach::kI}) {
    const std::string an = ncs::name(a);
    const nlohmann::json& e = rep.at("traces").at(an);
    EXPECT_TRUE(e.at("same_cost_as_sweep").get<bool>()) << an;
    EXPECT_NE(md.find("![" + an + " trace](trace_" + an + ".png)"), std::string::npos) << an;
    EXPECT_TRUE(std::filesystem::exists(out + "/trace_" + an + ".png")) << an;
    const auto states = csv_rows(out + "/trace_" + an + "_states.csv");
    ASSERT_GT(states.size(), 1U);
    EXPECT_EQ(states[0], (std::vector<std::string>{"t_s", "x1", "x2", "r1", "u"}));
    EXPECT_EQ(states.size(), 3002U) << an;  // header + every ms of 3 s
    EXPECT_EQ(std::filesystem::exists(out + "/trace_" + an + "_estimates.csv"), a == ncs::Approach::kOSK) << an;
    if (a == ncs::Approach::kOSK) {
      const auto est = csv_rows(out + "/trace_" + an + "_estimates.csv");
      EXPECT_EQ(est[0], (std::vector<std::string>{"t_s", "xhat1", "xhat2"}));
      EXPECT_GT(est.size(), 50U);  // a computation every h = 50 ms
    }
    // The message rows against the link counters of the same run (untraced).
    const ncs::RunResult run = ncs::run(*s.ctx, a, s.scenarios[0], s.first_seed, ncs::RunOptions{});
    EXPECT_EQ(e.at("cost").get<double>(), run.cost);
    const auto msgs = csv_rows(out + "/trace_" + an + "_messages.csv");
    ASSERT_FALSE(msgs.empty());
    EXPECT_EQ(msgs[0], (std::vector<std::string>{"leg", "leg_index", "sent_s", "arrival_s", "lost", "delivered"}));
    std::map<std::string, std::array<std::uint64_t, 3>> seen;  // sent, delivered, lost
    for (std::size_t i = 1; i < msgs.size(); ++i) {
      ASSERT_EQ(msgs[i].size(), 6U) << i;
      auto& c = seen[msgs[i][0]];
      ++c[0];
      const bool lost = msgs[i][4] == "1";
      EXPECT_EQ(msgs[i][5] == "1", !lost) << i;  // links: every message not lost has its arrival
      if (lost) {
        ++c[2];
        EXPECT_TRUE(msgs[i][3].empty()) << i;
      } else {
        ++c[1];
        EXPECT_GE(std::stod(msgs[i][3]), std::stod(msgs[i][2])) << i;
      }
    }
    ASSERT_FALSE(run.links.empty());
    std::uint64_t lost_total = 0;
    for (const auto& [leg, st] : run.links) {
      EXPECT_EQ(seen[leg][0], st.sent) << an << " " << leg;
      EXPECT_EQ(seen[leg][1], st.sent - st.lost) << an << " " << leg;
      EXPECT_EQ(seen[leg][2], st.lost) << an << " " << leg;
      EXPECT_EQ(e.at("messages").at(leg).at("lost").get<std::uint64_t>(), st.lost) << an << " " << leg;
      lost_total += st.lost;
    }
    EXPECT_EQ(seen.size(), run.links.size()) << an;
    if (a == ncs::Approach::kOSK) {
      EXPECT_GT(lost_total, 0U);  // the file's sc leg loses some in 3 s
    }
  }
}

TEST(StudyReport, NoPlotsWritesTheTracesCsvOnly) {
  const std::string out = test::fresh_dir("oneshot_study_report", "traces_no_plots");
  const test::CommandResult r = test::run_command({ONESHOT_SIM_PATH, "study", "report", kExample, out, "--seeds", "2", "--threads",
                                                   "2", "--max-duration", "2.5", "--no-plots", "--trace", "S,AK"});
  ASSERT_EQ(r.exit_code, 0) << r.output;
  std::size_t csv = 0;
  for (const auto& f : std::filesystem::directory_iterator(out)) {
    EXPECT_NE(f.path().extension(), ".png") << f.path();
    EXPECT_NE(f.path().extension(), ".gp") << f.path();
    csv += f.path().filename().string().rfind("trace_", 0) == 0 && f.path().extension() == ".csv";
  }
  EXPECT_EQ(csv, 5U);  // S: states, messages; AK: states, estimates, messages
  EXPECT_EQ(read_report_json(out + "/report.json").at("traces").size(), 2U);
}

/// `study bench` of the shipped example `example` on 2 seeds and 2 threads, runs of 2.5 s: its
/// JSON and the study it ran (mapped and capped as the command does); `dir` names the output folder.
std::pair<nlohmann::json, NcsStudy> bench_of(const std::string& example, const std::string& dir_name) {
  const std::string file = std::string(ONESHOT_STUDY_EXAMPLES_DIR) + "/" + example;
  const std::string dir = test::made_dir("oneshot_study_report", dir_name);
  const test::CommandResult r = test::run_command({ONESHOT_SIM_PATH, "study", "bench", file, "--seeds", "2", "--threads", "2",
                                                   "--max-duration", "2.5", "--json", dir + "/bench.json"});
  EXPECT_EQ(r.exit_code, 0) << r.output;
  NcsStudy s = map_ncs_study(engine::load_study(file, &ncs_schema()));
  cap_duration(s, 2.5, "--max-duration");
  return {r.exit_code == 0 ? read_report_json(dir + "/bench.json") : nlohmann::json::object(), std::move(s)};
}

TEST(StudyReport, BenchCountsTheSweepsKernelEvents) {
  // `study bench`'s events are the kernel events of the sweep's runs, counted here one run at a time.
  const auto [j, s] = bench_of("sod_ge_oneshot.json", "bench");
  ASSERT_FALSE(j.empty());
  double total = 0;
  for (ncs::Approach a : s.approaches) {
    double events = 0;
    for (const ncs::Scenario& x : s.scenarios)
      for (std::uint64_t seed = s.first_seed; seed < s.first_seed + 2; ++seed)
        events += static_cast<double>(ncs::run(*s.ctx, a, x, seed, ncs::RunOptions{}).events);
    EXPECT_EQ(j.at("per_approach").at(ncs::name(a)).at("events").get<double>(), events) << ncs::name(a);
    EXPECT_GT(events, 0);
    total += events;
  }
  EXPECT_EQ(j.at("events").get<double>(), total);
  EXPECT_EQ(j.at("runs").get<std::size_t>(), s.approaches.size() * s.scenarios.size() * 2);
  EXPECT_EQ(j.at("threads").get<unsigned>(), 2U);
  EXPECT_GT(j.at("wall_s").get<double>(), 0);
  EXPECT_NEAR(j.at("events_per_s_per_thread").get<double>(), total / j.at("wall_s").get<double>() / 2, 1e-9 * total);
}

TEST(StudyReport, BenchGivesEveryLoopsCost) {
  // A file with several loops: per approach every loop's mean cost over its shared runs.
  const auto [j, s] = bench_of("two_loops_can_phase.json", "bench_loops");
  ASSERT_FALSE(j.empty());
  for (ncs::Approach a : s.approaches) {
    std::vector<double> sum(s.loops.size(), 0.0);
    for (std::size_t x = 0; x < s.scenarios.size(); ++x)
      for (std::uint64_t seed = s.first_seed; seed < s.first_seed + 2; ++seed) {
        const std::vector<ncs::RunResult> runs = ncs::run_loops(loops_on_bus(s, x), a, seed);
        for (std::size_t i = 0; i < runs.size(); ++i) sum[i] += runs[i].cost;
      }
    for (std::size_t i = 0; i < s.loops.size(); ++i) {
      const double mean = sum[i] / static_cast<double>(2 * s.scenarios.size());
      EXPECT_NEAR(j.at("per_approach").at(ncs::name(a)).at("loops").at(s.loops[i].loop).at("cost_mean").get<double>(), mean,
                  1e-12 * mean)
          << ncs::name(a) << " " << s.loops[i].loop;
    }
  }
}

}  // namespace
}  // namespace oneshot::study
