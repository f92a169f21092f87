/// @file cpu_sampling_test.cpp
/// @brief Configurable sample and actuation points in a job (cpu_job_point.hpp): the
///        sampling jitter of a 2-task set follows its closed form for the start, the end and
///        a fraction; a preempted job's point is reached at the exact instant; random sets
///        keep every sampling, actuation and input-output latency inside the analysis bounds;
///        the on_point callback fires at exactly those instants and changes nothing; bad
///        points are refused naming the field.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

#include "oneshot/engine/cpu.hpp"
#include "oneshot/engine/cpu_analysis.hpp"
#include "oneshot/engine/json_fields.hpp"
#include "sim_host/engine/cpu_test_support.hpp"

namespace {

using namespace oneshot::engine;
using namespace oneshot::engine::cpu;

using test_support::task;

std::vector<CpuTaskStats> run(const TaskSet& set, SimTime duration, std::uint64_t seed) {
  return test_support::simulate(set, duration, seed);
}

JobPoint fraction(double f) {
  JobPoint p;
  p.kind = JobPoint::Kind::kFraction;
  p.fraction = f;
  return p;
}

/// hi (C 2, T 5, highest) and lo (C uniform {2, 3, 4} µs, T 10), synchronous, no switches.
/// lo's job starts after hi's: at start the sample latency is C_hi = 2 always (jitter 0);
/// at the end it is C_hi + C_lo, plus C_hi when C_hi + C_lo > T_hi: {4, 5, 8} (jitter 4 =
/// WCRT 8 − 4); at f = 0.5 (no preemption before it: C_hi + f·C_lo ≤ T_hi) it is
/// C_hi + ⌊f·C_lo⌋: 3, 3.5, 4 (jitter f·(C − C^b) = 1). The input-output latency from the
/// start to the end: {2, 3, 6}.
TEST(CpuSampling, TwoTaskClosedForm) {
  TaskSet s;
  s.tasks = {task("hi", 5, 2, 2, 1), task("lo", 10, 4, 2, 2)};
  const SimTime dur = from_us(20'000);
  auto jitter = [&](const JobPoint& p) {
    TaskSet v = s;
    v.tasks[1].sample_at = p;
    const CpuTaskStats st = run(v, dur, 3)[1];
    return std::pair<Duration, Duration>{st.sample_min, st.sample_max};
  };
  EXPECT_EQ(jitter(job_start()), (std::pair<Duration, Duration>{from_us(2), from_us(2)}));
  EXPECT_EQ(jitter(job_end()), (std::pair<Duration, Duration>{from_us(4), from_us(8)}));
  EXPECT_EQ(jitter(fraction(0.5)), (std::pair<Duration, Duration>{from_us(3), from_us(4)}));
  const CpuTaskStats st = run(s, dur, 3)[1];
  EXPECT_EQ(st.io_min, from_us(2));
  EXPECT_EQ(st.io_max, from_us(6));
  EXPECT_EQ(st.actuate_max - st.actuate_min, from_us(4));
  // The analysis bounds hold them: start [0, WCRT − C^b] = [0, 6], end [BCRT, WCRT] = [2, 8].
  const Analysis a = analyze(s);
  EXPECT_EQ(a.tasks[1].wcrt, from_us(8));
  EXPECT_EQ(a.tasks[1].sampling_latency_max, from_us(6));
  EXPECT_EQ(a.tasks[1].actuation_latency_max, from_us(8));
  EXPECT_EQ(a.tasks[1].io_latency_min, from_us(2));
}

/// lo (C 4, sample at 3 µs of work, switch 1 µs) preempted by hi (C 2, offset 2): lo switches
/// in 0–1, works 1–2, hi switches in and runs 2–5, lo switches back 5–6 and reaches 3 µs of
/// work at 8; actuation (end) at 9.
TEST(CpuSampling, PointReachedExactlyAcrossPreemption) {
  TaskSet s;
  s.context_switch = from_us(1);
  s.tasks = {task("hi", 100, 2, 2, 1), task("lo", 100, 4, 4, 2)};
  s.tasks[0].offset = from_us(2);
  JobPoint p;
  p.kind = JobPoint::Kind::kTime;
  p.time = from_us(3);
  s.tasks[1].sample_at = p;
  Kernel k(1);
  Cpu cpu(k, s);
  std::vector<CpuJob> jobs;
  cpu.on_job([&](const CpuJob& j) { jobs.push_back(j); });
  cpu.start(from_us(50));
  k.run_until(from_us(50));
  ASSERT_EQ(jobs.size(), 2U);
  EXPECT_EQ(jobs[1].entity, 1U);
  EXPECT_EQ(jobs[1].sample, from_us(8));
  EXPECT_EQ(jobs[1].actuate, from_us(9));
  EXPECT_EQ(jobs[0].sample, from_us(3));  // hi: start after its switch
}

/// 300 random fixed-priority and EDF sets (switches, an ISR, random sample/actuation points):
/// every simulated sampling, actuation and input-output latency inside the analysis bounds.
TEST(CpuSampling, RandomSetsStayWithinLatencyBounds) {
  RandomStream r(29, "cpu_sampling_test/random");
  const std::int64_t periods[] = {1000, 2000, 2500, 4000, 5000, 10000};
  std::size_t checked = 0;
  for (int n = 0; n < 300; ++n) {
    TaskSet s;
    s.scheduler = n % 2 == 0 ? SchedulerKind::kFixedPriority : SchedulerKind::kEdf;
    s.context_switch = from_us(r.uniform_int(0, 4));
    const std::int64_t nt = r.uniform_int(2, 5);
    const double u = r.uniform(0.3, 0.9);
    for (std::int64_t i = 0; i < nt; ++i) {
      const auto [p, w] = test_support::random_share(r, periods, u, nt, 2);
      TaskSpec t = task("t" + std::to_string(i), p, w, std::max<std::int64_t>(1, w / 3), static_cast<int>(i) + 1);
      t.offset = from_us(r.uniform_int(0, p - 1));
      JobPoint a = fraction(r.uniform(0.5, 1.0)), b = fraction(r.uniform(0.0, 0.5));
      if (r.bernoulli(0.3)) {
        b.kind = JobPoint::Kind::kTime;
        b.time = from_us(r.uniform_int(0, std::max<std::int64_t>(1, w / 3) / 2));  // before ⌊0.5·e⌋ for every e ≥ C^b
      }
      if (r.bernoulli(0.3)) a = job_end();
      t.sample_at = b;
      t.actuate_at = a;
      s.tasks.push_back(t);
    }
    if (r.bernoulli(0.5)) s.isrs.push_back(task("isr", 1000, r.uniform_int(1, 20), 1, 1));
    checked += test_support::check_bounded_tasks(
        s, from_us(200'000), static_cast<std::uint64_t>(n), [&](const CpuTaskStats& st, const TaskBound& b, const Analysis&) {
          const std::string m = "set " + std::to_string(n) + " " + b.name + "\n" + task_set_json(s).dump();
          ASSERT_GE(st.sample_min, b.sampling_latency_min) << m;
          ASSERT_LE(st.sample_max, b.sampling_latency_max) << m;
          ASSERT_GE(st.actuate_min, b.actuation_latency_min) << m;
          ASSERT_LE(st.actuate_max, b.actuation_latency_max) << m;
          ASSERT_GE(st.io_min, b.io_latency_min) << m;
          ASSERT_LE(st.io_max, b.io_latency_max) << m;
        });
    if (HasFatalFailure()) return;
  }
  EXPECT_GT(checked, 700U);
}

/// Cpu::on_point on 100 random sets (switches, an ISR, random points, preemptions): called at
/// exactly every finished task job's sample and actuation instants, once each, sample first;
/// the statistics equal those of the run without it (its events change nothing; `busy` may
/// differ by the unaccounted part of a segment running at the end).
TEST(CpuSampling, OnPointFiresAtEveryJobsPointsAndChangesNothing) {
  RandomStream r(31, "cpu_sampling_test/on_point");
  const std::int64_t periods[] = {1000, 2000, 2500, 4000, 5000, 10000};
  std::size_t jobs_checked = 0;
  for (int n = 0; n < 100; ++n) {
    TaskSet s;
    s.scheduler = n % 2 == 0 ? SchedulerKind::kFixedPriority : SchedulerKind::kEdf;
    s.context_switch = from_us(r.uniform_int(0, 4));
    const std::int64_t nt = r.uniform_int(2, 4);
    for (std::int64_t i = 0; i < nt; ++i) {
      const auto [p, w] = test_support::random_share(r, periods, r.uniform(0.3, 0.8), nt, 2);
      TaskSpec t = task("t" + std::to_string(i), p, w, std::max<std::int64_t>(1, w / 3), static_cast<int>(i) + 1);
      t.offset = from_us(r.uniform_int(0, p - 1));
      t.sample_at = r.bernoulli(0.5) ? job_start() : fraction(r.uniform(0.0, 0.5));
      t.actuate_at = r.bernoulli(0.5) ? job_end() : fraction(r.uniform(0.5, 1.0));
      s.tasks.push_back(t);
    }
    if (r.bernoulli(0.5)) s.isrs.push_back(task("isr", 1000, r.uniform_int(1, 20), 1, 1));
    const SimTime end = from_us(100'000);
    Kernel k0(static_cast<std::uint64_t>(n) + 1);
    Cpu plain(k0, s);
    plain.start(end);
    k0.run_until(end);
    Kernel k1(static_cast<std::uint64_t>(n) + 1);
    Cpu cpu(k1, s);
    std::vector<std::vector<std::pair<SimTime, SimTime>>> seen(s.tasks.size());  // per job: (sample, actuate) told
    cpu.on_point([&](std::size_t e, std::uint64_t index, CpuEventKind kind) {
      ASSERT_LT(e, s.tasks.size());
      if (seen[e].size() <= index) seen[e].resize(index + 1, {SimTime{-1}, SimTime{-1}});
      SimTime& at = kind == CpuEventKind::kSample ? seen[e][index].first : seen[e][index].second;
      ASSERT_EQ(at, SimTime{-1}) << "told twice";
      if (kind == CpuEventKind::kActuate) {
        ASSERT_NE(seen[e][index].first, SimTime{-1}) << "actuation before the sample";
      }
      at = k1.now();
    });
    cpu.on_job([&](const CpuJob& j) {
      if (j.entity >= s.tasks.size() || j.aborted) return;
      ASSERT_LT(j.index, seen[j.entity].size());
      EXPECT_EQ(seen[j.entity][j.index].first, j.sample) << "set " << n;
      EXPECT_EQ(seen[j.entity][j.index].second, j.actuate) << "set " << n;
      ++jobs_checked;
    });
    cpu.start(end);
    k1.run_until(end);
    if (HasFatalFailure()) return;
    for (std::size_t e = 0; e < cpu.stats().size(); ++e) {
      EXPECT_EQ(cpu.stats()[e].finished, plain.stats()[e].finished) << "set " << n;
      EXPECT_EQ(cpu.stats()[e].response_max, plain.stats()[e].response_max) << "set " << n;
      EXPECT_EQ(cpu.stats()[e].sample_max, plain.stats()[e].sample_max) << "set " << n;
      EXPECT_EQ(cpu.stats()[e].actuate_max, plain.stats()[e].actuate_max) << "set " << n;
    }
  }
  EXPECT_GT(jobs_checked, 5000U);
}


std::string refusal(const std::string& task_extra) {
  const std::string text = R"({"scheduler": "fixed_priority", "tasks": [{"name": "a", "period_us": 1000, "wcet_us": 100, "bcet_us": 50, "priority": 1)" +
                           task_extra + "}]}";
  try {
    parse_task_set(text, "t.json", "");
  } catch (const InputError& e) {
    return e.what();
  }
  return "accepted";
}

/// Bad points are refused naming the field; good ones parse (file and command-line forms).
TEST(CpuSampling, BadPointsRefusedNamingTheField) {
  EXPECT_NE(refusal(R"(, "sample_at": 1.5)").find("'tasks[0].sample_at'"), std::string::npos);
  EXPECT_NE(refusal(R"(, "sample_at": "middle")").find("'tasks[0].sample_at'"), std::string::npos);
  EXPECT_NE(refusal(R"(, "sample_at": {"instructions": 300})").find("'tasks[0].sample_at.clock_mips'"), std::string::npos);
  EXPECT_NE(refusal(R"(, "sample_at": {"fraction": 0.2, "us": 3})").find("'tasks[0].sample_at'"), std::string::npos);
  EXPECT_NE(refusal(R"(, "sample_at": {"cycles": 3})").find("tasks[0].sample_at"), std::string::npos);
  EXPECT_NE(refusal(R"(, "sample_at": "end", "actuate_at": "start")").find("'tasks[0].actuate_at'"), std::string::npos);
  EXPECT_NE(refusal(R"(, "sample_at": {"us": 80}, "actuate_at": 0.9)").find("'tasks[0].actuate_at'"), std::string::npos);
  EXPECT_EQ(refusal(R"(, "sample_at": 0.25, "actuate_at": {"us": 90})"), "accepted");
  EXPECT_EQ(refusal(R"(, "sample_at": {"instructions": 300, "clock_mips": 40})"), "accepted");
  EXPECT_EQ(parse_job_point_text("1200instr", "--sample-at", 40).offset(from_us(100)), from_us(30));
  EXPECT_EQ(parse_job_point_text("0.25", "--sample-at", 40).offset(from_us(100)), from_us(25));
  EXPECT_EQ(parse_job_point_text("300us", "--sample-at", 40).offset(from_us(100)), from_us(100));
  EXPECT_THROW(parse_job_point_text("half", "--sample-at", 40), InputError);
  EXPECT_THROW(parse_job_point_text("2", "--sample-at", 40), InputError);
}

}  // namespace
