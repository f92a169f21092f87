/// @file study_files_test.cpp
/// @brief `study run` of an ncs study file: the same costs as `ncs table` on the same seeds
///        (the file's legs against the table's built-in ones), with --analytic the same
///        figures as `ncs table --analytic` and refused approaches reported with the reason,
///        per-link counters, shards merged to the same bytes as one run (with and without
///        --analytic), the refusals of what the loop cannot run, and the NEES of every filter
///        (the well-tuned AKx consistent, SK's not, IK's free of the noise scale).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>

#include "ncs_experiments.hpp"
#include "ncs_loop.hpp"
#include "oneshot/engine/study_file.hpp"
#include "study_ncs_runner.hpp"
#include "study_ncs_sweep.hpp"
#include "study_sweep_checks.hpp"
#include "support/temp_files.hpp"

namespace oneshot::study {
namespace {

std::string example_path() { return std::string(ONESHOT_STUDY_EXAMPLES_DIR) + "/ncs.json"; }

nlohmann::json example_json() { return nlohmann::json::parse(test::read_file(example_path())); }

/// The file's text after `edit`, parsed with the ncs schema as if it sat beside the example.
engine::StudyFile parse_edited(const std::function<void(nlohmann::json&)>& edit) {
  nlohmann::json j = example_json();
  edit(j);
  return engine::parse_study(j.dump(), example_path(), &ncs_schema(), ONESHOT_STUDY_EXAMPLES_DIR);
}

/// A path under the temporary folder, unique to this process (removed first).
std::string temp_dir(const char* name) { return test::fresh_dir("oneshot_study_test", name); }

/// Scenarios 0 (d = 4), 1 (d = 14), 2 (d = 8) of the file, `duration_s` long.
NcsStudy small_study(double duration_s) {
  NcsStudy s = map_ncs_study(engine::load_study(example_path(), &ncs_schema()));
  s.scenarios.resize(3);
  for (ncs::Scenario& x : s.scenarios) x.duration_s = duration_s;
  return s;
}

TEST(StudyFiles, NcsFileGivesTheCostsOfNcsTable) {
  const NcsStudy s = small_study(4);
  ASSERT_EQ(s.approaches.size(), 9U);
  const engine::SweepResults mine = run_ncs_sweep(s, 3, 2, engine::Shard{});
  const nlohmann::json jm = run_outputs(mine, temp_dir("costs_study"), false);
  ncs::TableOptions t;  // the table's own scenarios: legs built from d, no file involved
  t.seeds = 3;
  t.threads = 2;
  t.scenarios = ncs::default_scenarios();
  t.scenarios.resize(3);
  for (ncs::Scenario& x : t.scenarios) x.duration_s = 4;
  const nlohmann::json jt = ncs::table_outputs(ncs::table_sweep(*s.ctx, t, engine::Shard{}), temp_dir("costs_table"), false);
  for (const auto& [name, a] : jt.at("approaches").items()) {
    const double want = a.at("cost_mean").get<double>();
    const double got = jm.at("approaches").at(name).at("cost_mean").get<double>();
    EXPECT_LE(std::fabs(got - want), 1e-12 * std::fabs(want)) << name;
    EXPECT_LE(std::fabs(jm.at("approaches").at(name).at("cost_ci95").get<double>() - a.at("cost_ci95").get<double>()),
              1e-12 * std::fabs(a.at("cost_ci95").get<double>()))
        << name;
  }
  for (const auto& [pair, d] : jt.at("paired_differences").items()) {
    EXPECT_LE(std::fabs(jm.at("paired_differences").at(pair).at("mean").get<double>() - d.at("mean").get<double>()),
              1e-12 * std::fmax(1e-12, std::fabs(d.at("mean").get<double>())))
        << pair;
  }
  EXPECT_TRUE(jm.at("approaches").at("AK").contains("ratio_to_I"));
  // Lossless legs: every frame sent is delivered; A uses all three legs, S only sc and ca.
  for (const char* leg : {"as", "sc", "ca"}) {
    const nlohmann::json& c = jm.at("links").at("A").at(leg);
    EXPECT_GT(c.at("sent").get<double>(), 0) << leg;
    EXPECT_EQ(c.at("lost").get<double>(), 0) << leg;
    EXPECT_EQ(c.at("delivered").get<double>(), c.at("sent").get<double>()) << leg;
  }
  EXPECT_EQ(jm.at("links").at("S").at("as").at("sent").get<double>(), 0);
  // ncs table keys S's ratio by d; a file's legs have no d: left out, the sc + ca delay bound
  // reported per scenario instead (legs U[0.5, d] ms: 2 d).
  EXPECT_TRUE(jt.contains("S_ratio_to_I_by_delay_ms"));
  EXPECT_FALSE(jm.contains("S_ratio_to_I_by_delay_ms"));
  EXPECT_FALSE(jm.contains("S_ratio_increases_with_delay"));
  ASSERT_EQ(jm.at("delay_bound_sc_ca_ms").size(), t.scenarios.size());
  for (const ncs::Scenario& x : t.scenarios) {
    EXPECT_NEAR(jm.at("delay_bound_sc_ca_ms").at(x.name).get<double>(), 2 * x.max_delay_ms, 1e-12) << x.name;
  }
}

TEST(StudyFiles, LossFromTheFileReachesTheLeg) {
  const engine::StudyFile f = parse_edited([](nlohmann::json& j) {
    j["links"][1]["loss"] = {{"model", "bernoulli"}, {"p", 0.2}};
    j["approaches"] = nlohmann::json::parse(R"([{"name": "I"}, {"name": "AK"}])");
  });
  NcsStudy s = map_ncs_study(f);
  s.scenarios.resize(1);
  s.scenarios[0].duration_s = 10;
  const nlohmann::json j = run_outputs(run_ncs_sweep(s, 3, 2, engine::Shard{}), temp_dir("loss"), false);
  const nlohmann::json& sc = j.at("links").at("AK").at("sc");
  const double sent = sc.at("sent").get<double>();
  ASSERT_GT(sent, 500);
  // Binomial: σ of the rate ≈ sqrt(0.2·0.8/600) ≈ 0.016; allow 4σ.
  EXPECT_NEAR(sc.at("lost").get<double>() / sent, 0.2, 0.065);
  EXPECT_EQ(sc.at("delivered").get<double>() + sc.at("lost").get<double>(), sent);
  EXPECT_EQ(j.at("links").at("AK").at("ca").at("lost").get<double>(), 0);
}

TEST(StudyFiles, LinkCountersCountFrames) {
  // Every command lost: no frame reaches the actuator, so none is dropped late there (the
  // periods without a command are the approach's late_commands, every one of them).
  const engine::StudyFile f = parse_edited([](nlohmann::json& j) {
    j["links"][2]["loss"] = {{"model", "bernoulli"}, {"p", 1}};
    j["approaches"] = nlohmann::json::parse(R"([{"name": "I"}, {"name": "S"}, {"name": "A"}, {"name": "AK"}])");
  });
  NcsStudy s = map_ncs_study(f);
  s.scenarios.resize(1);
  s.scenarios[0].duration_s = 2;
  const nlohmann::json j = run_outputs(run_ncs_sweep(s, 2, 2, engine::Shard{}), temp_dir("frames"), false);
  for (const char* a : {"S", "A", "AK"}) {
    const nlohmann::json& ca = j.at("links").at(a).at("ca");
    EXPECT_GT(ca.at("sent").get<double>(), 0) << a;
    EXPECT_EQ(ca.at("lost").get<double>(), ca.at("sent").get<double>()) << a;
    EXPECT_EQ(ca.at("late").get<double>(), 0) << a;
    EXPECT_EQ(ca.at("refused").get<double>(), 0) << a;
  }
  for (const char* a : {"A", "AK"}) EXPECT_GT(j.at("approaches").at(a).at("late_commands").get<double>(), 0) << a;
  // Every link and approach: frames dropped or refused by the receiver were delivered first.
  for (const auto& [a, links] : j.at("links").items())
    for (const auto& [l, c] : links.items())
      EXPECT_LE(c.at("late").get<double>() + c.at("refused").get<double>(), c.at("delivered").get<double>()) << a << " " << l;
}

TEST(StudyFiles, LateCountsCommandsTheActuatorDropsAsStale) {
  // Commands delayed up to 1.5 h, overtaking allowed: some reach the actuator after a newer one
  // or after their actuation instant, and it drops them as stale: the link's late counter.
  const engine::StudyFile f = parse_edited([](nlohmann::json& j) {
    j["links"][2]["delay"] = {{"model", "uniform"}, {"min_us", 500}, {"max_us", 75000}, {"resolution_us", 1}};
    j["links"][2]["order"] = "any";
    j["approaches"] = nlohmann::json::parse(R"([{"name": "I"}, {"name": "S"}, {"name": "A"}, {"name": "AK"}])");
  });
  NcsStudy s = map_ncs_study(f);
  s.scenarios.resize(1);
  s.scenarios[0].duration_s = 2;
  const nlohmann::json j = run_outputs(run_ncs_sweep(s, 2, 2, engine::Shard{}), temp_dir("stale"), false);
  for (const char* a : {"A", "AK"}) {
    const nlohmann::json& ca = j.at("links").at(a).at("ca");
    EXPECT_GT(ca.at("late").get<double>(), 0) << a;
    EXPECT_LE(ca.at("late").get<double>() + ca.at("refused").get<double>(), ca.at("delivered").get<double>()) << a;
  }
}

/// `want` and `got` equal within 1e-12 relative (both null, or both numbers).
void expect_same_figure(const nlohmann::json& got, const nlohmann::json& want, const std::string& what) {
  if (want.is_null()) {
    EXPECT_TRUE(got.is_null()) << what;
    return;
  }
  ASSERT_TRUE(got.is_number()) << what;
  const double w = want.get<double>();
  EXPECT_LE(std::fabs(got.get<double>() - w), 1e-12 * std::fabs(w)) << what << ": " << got << " vs " << w;
}

TEST(StudyFiles, AnalyticRunGivesTheFiguresOfNcsTableAnalytic) {
  const NcsStudy s = small_study(4);
  ASSERT_EQ(s.approaches.size(), 9U);
  const nlohmann::json jm = run_outputs(run_ncs_sweep(s, 3, 2, engine::Shard{}, true), temp_dir("analytic_study"), false);
  ncs::TableOptions t;  // the table's own scenarios: legs built from d, no file involved
  t.seeds = 3;
  t.threads = 2;
  t.analytic = true;
  t.scenarios = ncs::default_scenarios();
  t.scenarios.resize(3);
  for (ncs::Scenario& x : t.scenarios) x.duration_s = 4;
  const nlohmann::json jt =
      ncs::table_outputs(ncs::table_sweep(*s.ctx, t, engine::Shard{}), temp_dir("analytic_table"), false);
  std::size_t compared = 0;
  for (const auto& [name, a] : jt.at("approaches").items()) {
    const nlohmann::json& m = jm.at("approaches").at(name);
    EXPECT_EQ(a.contains("analytic_refused"), m.contains("analytic_refused")) << name;
    for (const auto& [key, want] : a.items()) {
      if (key.rfind("analytic_", 0) != 0 && key.rfind("mc_minus_analytic", 0) != 0 && key != "variance_reduction") continue;
      ASSERT_TRUE(m.contains(key)) << name << " " << key;
      if (want.is_string()) {
        EXPECT_EQ(m.at(key), want) << name << " " << key;
      } else {
        expect_same_figure(m.at(key), want, name + " " + key);
        ++compared;
      }
    }
  }
  EXPECT_GE(compared, 9U * 6U);  // every approach has its analytic figures (none refused here)
  ASSERT_TRUE(jt.contains("analytic_paired_differences"));
  for (const auto& [pair, d] : jt.at("analytic_paired_differences").items()) {
    const nlohmann::json& m = jm.at("analytic_paired_differences").at(pair);
    expect_same_figure(m.at("mean"), d.at("mean"), pair);
    expect_same_figure(m.at("ci95"), d.at("ci95"), pair + " ci95");
  }
  expect_same_figure(jm.at("variance_reduction"), jt.at("variance_reduction"), "variance_reduction");
  expect_same_figure(jm.at("variance_reduction_median"), jt.at("variance_reduction_median"), "variance_reduction_median");
  EXPECT_NE(jm.at("markdown").get<std::string>().find("analytic mean"), std::string::npos);
}

TEST(StudyFiles, AnalyticRunReportsRefusedApproachesWithTheReason) {
  // A lossy sc leg: a lost sample or request leaves the loop the analytic tracker follows, so
  // S and AK are refused (reported with the reason, never dropped); I has no legs and is exact.
  const engine::StudyFile f = parse_edited([](nlohmann::json& j) {
    j["links"][1]["loss"] = {{"model", "bernoulli"}, {"p", 0.2}};
    j["approaches"] = nlohmann::json::parse(R"([{"name": "I"}, {"name": "S"}, {"name": "AK"}])");
  });
  NcsStudy s = map_ncs_study(f);
  s.scenarios.resize(1);
  s.scenarios[0].duration_s = 4;
  const nlohmann::json j = run_outputs(run_ncs_sweep(s, 3, 2, engine::Shard{}, true), temp_dir("analytic_loss"), false);
  const nlohmann::json& ji = j.at("approaches").at("I");
  EXPECT_FALSE(ji.contains("analytic_refused"));
  EXPECT_TRUE(std::isfinite(ji.at("analytic_mean").get<double>()));
  for (const char* name : {"S", "AK"}) {
    const nlohmann::json& a = j.at("approaches").at(name);
    ASSERT_TRUE(a.contains("analytic_refused")) << name;
    const std::string reason = a.at("analytic_refused").get<std::string>();
    EXPECT_FALSE(reason.empty()) << name;
    EXPECT_NE(reason, "unknown") << name;
    EXPECT_GT(a.at("analytic_refused_runs").get<std::size_t>(), 0U) << name;
    EXPECT_FALSE(a.contains("analytic_mean")) << name;
    EXPECT_NE(j.at("markdown").get<std::string>().find(std::string("| ") + name + " | refused ("), std::string::npos) << name;
  }
  // No figure is taken from the refused runs' zeros: no pair with S or AK.
  EXPECT_FALSE(j.contains("analytic_paired_differences"));
}

TEST(StudyFiles, MergedShardsGiveTheSameBytesAsOneRun) {
  NcsStudy s = small_study(2);
  s.approaches = {ncs::Approach::kI, ncs::Approach::kS, ncs::Approach::kAK};
  for (const bool analytic : {false, true}) {
    const std::string whole =
        run_outputs(run_ncs_sweep(s, 4, 2, engine::Shard{}, analytic), temp_dir("whole"), false).dump();
    const std::string merged = test_support::merged_shard_outputs(s, 4, temp_dir("merged"), analytic).dump();
    EXPECT_EQ(merged, whole) << "analytic " << analytic;
    EXPECT_EQ(nlohmann::json::parse(whole).contains("variance_reduction"), analytic);
  }
}

TEST(StudyFiles, SharedIntervalCachesGiveTheSameBytesAsEachRunItsOwn) {
  NcsStudy s = small_study(2);  // A, AK, S+: plant events at ever different offsets; I on a fixed grid
  s.approaches = {ncs::Approach::kI, ncs::Approach::kA, ncs::Approach::kAK, ncs::Approach::kSPlus};
  const auto outputs = [&](unsigned threads, bool shared, const char* dir) {
    const engine::SweepResults r = run_ncs_sweep(s, 3, threads, engine::Shard{}, false, shared);
    return engine::shard_to_json(r).dump() + run_outputs(r, temp_dir(dir), false).dump();
  };
  const std::string own = outputs(1, false, "own");
  EXPECT_EQ(outputs(1, true, "shared1"), own);
  EXPECT_EQ(outputs(2, true, "shared2"), own);
}

/// A refusal names the field; `expect` is a fragment of the message.
void expect_refused(const std::function<void(nlohmann::json&)>& edit, const std::string& expect) {
  try {
    static_cast<void>(map_ncs_study(parse_edited(edit)));
    ADD_FAILURE() << "accepted, expected " << expect;
  } catch (const engine::InputError& e) {
    EXPECT_NE(std::string(e.what()).find(expect), std::string::npos) << e.what();
  }
}

TEST(StudyFiles, WhatTheLoopCannotRunIsRefusedNamingTheField) {
  expect_refused([](nlohmann::json& j) { j["nodes"][1]["clock_offset_us"] = 50000; }, "field 'nodes[1].clock_offset_us'");  // = h
  expect_refused([](nlohmann::json& j) { j["nodes"][0]["address"] = 7; }, "field 'nodes[0].address'");
  expect_refused([](nlohmann::json& j) { j["nodes"][0]["period_us"] = 40000; }, "field 'nodes[0].period_us'");
  expect_refused([](nlohmann::json& j) { j["nodes"][1]["mode"] = "timer"; j["nodes"][1]["period_us"] = 50000; },
                 "field 'nodes[1].mode'");
  expect_refused([](nlohmann::json& j) { j["nodes"][0]["trigger"] = {{"rule", "periodic"}, {"every", 2}}; },
                 "field 'nodes[0].trigger'");
  expect_refused(
      [](nlohmann::json& j) {
        j["buses"] = nlohmann::json::parse(R"([{"name": "can0", "bit_rate": 500000}])");
      },
      "field 'buses[0]'");  // a bus no leg runs on
  const auto drop_as_overrides = [](nlohmann::json& j) {
    for (auto& sc : j["scenarios"])
      if (sc.contains("links")) sc["links"].erase("as");
  };
  expect_refused([&](nlohmann::json& j) { drop_as_overrides(j); j["links"][0]["name"] = "back"; }, "field 'links[0].name'");
  expect_refused([&](nlohmann::json& j) { drop_as_overrides(j); j["links"].erase(0); }, "field 'approaches[2].kind'");  // A needs as
  expect_refused([](nlohmann::json& j) { j["approaches"][0]["name"] = "ideal"; }, "field 'approaches[0].name'");
  expect_refused([](nlohmann::json& j) { std::swap(j["approaches"][0], j["approaches"][1]); }, "field 'approaches[0].kind'");
  expect_refused([](nlohmann::json& j) { j["scenarios"][0]["params"]["period_s"] = 0.125; }, "field 'scenarios[0].params.period_s'");
  // I, the reference of every ratio, would cost exactly 0: it starts on the set-point, without delay or noise.
  expect_refused([](nlohmann::json& j) { j["scenarios"][0]["params"]["amplitude_volts"] = 0; },
                 "field 'scenarios[0].params.amplitude_volts'");
  expect_refused([](nlohmann::json& j) { j["scenarios"][2]["duration_s"] = 2; }, "field 'scenarios[2].duration_s'");  // T_r/2 = 2 s
  expect_refused([](nlohmann::json& j) { j["duration_s"] = 0.5; }, "field 'duration_s'");
  expect_refused([](nlohmann::json& j) {
    j["plant"] = {{"continuous", {{"A", {{0}}}, {"B", {{1, 1, 1, 1, 1}}}, {"C", {{1}}}, {"Q_c", {{0}}}}}};
  }, "field 'plant.continuous.B': dimensions n = 1, m = 5");  // m ≤ 4
  // S+ needs a mean delay below h: 45 + 2.25 + 3 ms is not.
  expect_refused([](nlohmann::json& j) { j["links"][1]["delay"] = {{"model", "constant"}, {"delay_us", 45000}}; },
                 "with approach S+");
  // AKl needs bounded legs.
  expect_refused(
      [](nlohmann::json& j) {
        j["links"][2]["delay"] = {{"model", "lognormal"}, {"median_us", 1000}, {"sigma", 0.5}};
      },
      "with approach AKl");
  // The schema refuses unknown kinds and parameters (parse_study).
  EXPECT_THROW(parse_edited([](nlohmann::json& j) { j["approaches"][1]["kind"] = "Z"; }), engine::InputError);
  EXPECT_THROW(parse_edited([](nlohmann::json& j) { j["scenarios"][0]["params"]["d"] = 3; }), engine::InputError);
}

TEST(StudyFiles, NeesOfEveryFilterAndTheWellTunedOneIsConsistent) {
  // Every approach whose controller runs a Kalman filter reports its NEES (n = 2): e = x − x̂ against
  // the filter's own P. AKx (the half Kalman filter with the exact Q_d(τ) of each interval) is the
  // loop's model: its mean NEES over seeds lies within three 95 % intervals of n (plus 1 % for the
  // first steps from P0 = 10 R). IK, delay-free, is scale-free: at noise scale s the error grows
  // as √s and P as s, so with the same normalized draws its NEES is the same in every scenario.
  // SK's filter takes the input as applied at the sample (it is applied τ later): its NEES is far
  // above n. A has no filter, no NEES.
  NcsStudy s = map_ncs_study(engine::load_study(example_path(), &ncs_schema()));
  s.approaches = {ncs::Approach::kI, ncs::Approach::kA, ncs::Approach::kAKx, ncs::Approach::kSK, ncs::Approach::kIK};
  s.scenarios = {s.scenarios[0], s.scenarios[3]};  // s = 1, d = 4 ms; s = 4, d = 14 ms
  const nlohmann::json j = run_outputs(run_ncs_sweep(s, 20, 2, engine::Shard{}), temp_dir("nees"), false);
  const nlohmann::json& nees = j.at("nees");
  EXPECT_FALSE(nees.contains("A"));
  EXPECT_FALSE(nees.contains("I"));
  const double akx = nees.at("AKx").at("nees_mean").get<double>();
  const double akx_ci = nees.at("AKx").at("nees_ci95").get<double>();
  EXPECT_LT(std::fabs(akx - 2.0), 3 * akx_ci + 0.02) << akx << " +- " << akx_ci;
  EXPECT_LT(akx_ci, 0.3);
  const double sk = nees.at("SK").at("nees_mean").get<double>();
  EXPECT_GT(sk - 3 * nees.at("SK").at("nees_ci95").get<double>(), 2.0) << sk;
  const nlohmann::json& ik = nees.at("IK").at("per_scenario");
  const double ik0 = ik.at(s.scenarios[0].name).at("nees_mean").get<double>();
  EXPECT_NEAR(ik.at(s.scenarios[1].name).at("nees_mean").get<double>(), ik0, 1e-9 * ik0);
  EXPECT_EQ(nees.at("IK").at("steps").get<double>(), 20 * 2 * 400);  // one per sample: 20 s at h = 50 ms
  EXPECT_NE(j.at("markdown").get<std::string>().find("| AKx | "), std::string::npos);
}

TEST(StudyFiles, NeesOfTheFirstFilterStepIsChiSquareOverSeeds) {
  // IK's first computation, at t = 0: the filter starts on the true state x0 with P0 = 10 R and
  // corrects with y0 = x0 + v0 (C = I, R diagonal): K = 10/11 I, e = −K v0, P = 10/11 R, so its
  // NEES is 10/11 v0ᵀ R⁻¹ v0 = 10/11 χ²(2). Over M seeds 11/10 Σ NEES is χ²(2M): within the
  // two-sided 99.9 % interval (Wilson–Hilferty), one NEES term per run of one period.
  NcsStudy s = map_ncs_study(engine::load_study(example_path(), &ncs_schema()));
  ncs::Scenario x = s.scenarios[0];
  x.duration_s = static_cast<double>(s.ctx->period_us()) * 1e-6;
  const int m = 400;
  double sum = 0;
  for (int seed = 1; seed <= m; ++seed) {
    const ncs::RunResult r = ncs::run(*s.ctx, ncs::Approach::kIK, x, static_cast<std::uint64_t>(seed), ncs::RunOptions{});
    ASSERT_EQ(r.nees_steps, 1U);
    sum += r.nees * 11.0 / 10.0;
  }
  const double k = 2.0 * m;
  const auto quantile = [k](double z) { return k * std::pow(1 - 2 / (9 * k) + z * std::sqrt(2 / (9 * k)), 3); };
  std::printf("IK first-step NEES: 11/10 sum over %d seeds %.1f, chi2(%.0f) 99.9 %% interval [%.1f, %.1f]\n", m, sum, k,
              quantile(-3.29), quantile(3.29));
  EXPECT_GT(sum, quantile(-3.29)) << sum;
  EXPECT_LT(sum, quantile(3.29)) << sum;
}

TEST(StudyFiles, OtherStudiesAreRefusedNamingTheStudyField) {
  const engine::StudyFile f = engine::load_study(ONESHOT_ENGINE_EXAMPLE_STUDY, nullptr);
  try {
    static_cast<void>(map_ncs_study(f));
    ADD_FAILURE() << "accepted";
  } catch (const engine::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("field 'study'"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace oneshot::study
