/// @file cpu_edf_rta_test.cpp
/// @brief EDF response-time analysis (Spuri) against a hand-computed set and an independent
///        brute force: small integer task sets simulated for every offset of the analysed
///        task (the others synchronous) and random offset patterns; the simulated maximum
///        never exceeds the analytic WCRT and equals it for some offset; random sets with
///        jitter, switches, ISRs and non-preemptive sections stay in [BCRT, WCRT].
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <numeric>
#include <string>
#include <vector>

#include "oneshot/engine/cpu.hpp"
#include "oneshot/engine/cpu_analysis.hpp"
#include "sim_host/engine/cpu_test_support.hpp"

namespace {

using namespace oneshot::engine;
using namespace oneshot::engine::cpu;

/// A periodic EDF task in whole µs with relative deadline `deadline_us`.
TaskSpec edf_task(const std::string& name, std::int64_t period_us, std::int64_t wcet_us, std::int64_t bcet_us, std::int64_t deadline_us,
                  int prio) {
  TaskSpec t = test_support::task(name, period_us, wcet_us, bcet_us, prio);
  t.deadline = from_us(deadline_us);
  return t;
}

std::vector<CpuTaskStats> run(const TaskSet& set, SimTime duration, std::uint64_t seed) {
  return test_support::simulate(set, duration, seed);
}

/// Hand computation (Spuri's candidates, docs/kernel.md): A (C 2, T = D 5), B (C 4, T = D 7).
/// B: L = 14, candidates x ∈ {0, 3, 7, 8, 13}, w − x = 6, 5, 5, 6, 1: WCRT 6 (synchronous).
/// A: candidates {0, 2, 5, 9, 10}, w − x = 2, 4, 3, 3, 4: WCRT 4 (A arrives 2 after B, equal
/// deadlines 7, B keeps the CPU). Rate monotonic would give A 2 and B 8.
TEST(CpuEdfRta, HandComputedSet) {
  TaskSet s;
  s.scheduler = SchedulerKind::kEdf;
  s.tasks = {edf_task("A", 5, 2, 2, 5, 2), edf_task("B", 7, 4, 4, 7, 1)};
  const Analysis a = analyze(s);
  ASSERT_TRUE(a.schedulable);
  EXPECT_EQ(a.tasks[0].wcrt, from_us(4));
  EXPECT_EQ(a.tasks[1].wcrt, from_us(6));
  EXPECT_EQ(a.tasks[0].bcrt, from_us(2));
  EXPECT_EQ(a.tasks[1].jobs_examined, 5U);
  // A (lowest priority: ties against it) arriving 2 µs after B: the simulated response is 4.
  s.tasks[0].offset = from_us(2);
  EXPECT_EQ(run(s, from_us(200), 1)[0].response_max, from_us(4));
}

/// 120 random integer sets of 2–3 tasks (T 3–9 µs, D from C to T + 3, U ≤ 1, constant C): for
/// each task i (the lowest priority, so EDF ties go against it) every offset of i in [0, T_i)
/// with the others synchronous, plus 20 random patterns of every offset: the simulated
/// maximum response ≤ the analytic WCRT, and = it for some offset (Spuri's bound is exact
/// for such sets).
TEST(CpuEdfRta, BruteForceOffsetsReachTheBound) {
  RandomStream r(22, "cpu_edf_rta_test/brute");
  int sets = 0, reached = 0, tasks = 0;
  while (sets < 120) {
    TaskSet s;
    s.scheduler = SchedulerKind::kEdf;
    const std::int64_t n = r.uniform_int(2, 3);
    double u = 0;
    std::int64_t h = 1;
    for (std::int64_t k = 0; k < n; ++k) {
      const std::int64_t t = r.uniform_int(3, 9), c = r.uniform_int(1, std::max<std::int64_t>(1, t / 2));
      s.tasks.push_back(edf_task("t" + std::to_string(k), t, c, c, r.uniform_int(c, t + 3), 1));
      u += static_cast<double>(c) / static_cast<double>(t);
      h = std::lcm(h, t);
    }
    if (u > 1.0) continue;
    ++sets;
    for (std::size_t i = 0; i < s.tasks.size(); ++i) {
      TaskSet v = s;
      v.tasks[i].priority = 2;
      const Analysis a = analyze(v);
      const TaskBound& b = a.tasks[i];
      ASSERT_TRUE(b.bounded);
      const SimTime dur = from_us(3 * h + 40);
      Duration best{0};
      for (std::int64_t o = 0; o < s.tasks[i].period.count() / 1000; ++o) {
        v.tasks[i].offset = from_us(o);
        for (TaskSpec& t : v.tasks) {
          if (&t != &v.tasks[i]) t.offset = Duration{0};
        }
        best = std::max(best, run(v, dur, 1)[i].response_max);
      }
      for (int p = 0; p < 20; ++p) {
        for (TaskSpec& t : v.tasks) t.offset = from_us(r.uniform_int(0, t.period.count() / 1000 - 1));
        const Duration m = run(v, dur, 1)[i].response_max;
        ASSERT_LE(m, b.wcrt) << "set " << sets << " task " << i << "\n" << task_set_json(v).dump();
      }
      ASSERT_LE(best, b.wcrt) << "set " << sets << " task " << i << "\n" << task_set_json(v).dump();
      EXPECT_EQ(best, b.wcrt) << "set " << sets << " task " << i << "\n" << task_set_json(v).dump();
      ++tasks;
      if (best == b.wcrt) ++reached;
    }
  }
  RecordProperty("tasks", tasks);
  RecordProperty("wcrt_reached", reached);
}

/// 400 random EDF sets (U 0.3–1.0, 2–6 tasks, deadlines T/2–2T, uniform execution, offsets;
/// half with release jitter, context switches, an ISR and non-preemptive sections): every
/// simulated response time within [BCRT, WCRT]; a set found schedulable misses nothing.
TEST(CpuEdfRta, RandomSetsStayWithinBounds) {
  RandomStream r(23, "cpu_edf_rta_test/random");
  const std::int64_t periods[] = {1000, 2000, 2500, 4000, 5000, 8000, 10000, 20000};
  std::size_t checked = 0;
  for (int n = 0; n < 400; ++n) {
    TaskSet s;
    s.scheduler = SchedulerKind::kEdf;
    const bool extras = n % 2 == 1;
    if (extras) s.context_switch = from_us(r.uniform_int(0, 5));
    const std::int64_t nt = r.uniform_int(2, 6);
    const double u = r.uniform(0.3, 1.0);
    for (std::int64_t i = 0; i < nt; ++i) {
      const auto [p, w] = test_support::random_share(r, periods, u, nt, 1);
      const std::int64_t d = std::max<std::int64_t>(w, std::llround(static_cast<double>(p) * r.uniform(0.5, 2.0)));
      TaskSpec t = edf_task("t" + std::to_string(i), p, w, std::max<std::int64_t>(1, std::llround(static_cast<double>(w) * r.uniform(0.2, 1.0))), d,
                            static_cast<int>(r.uniform_int(1, 3)));
      t.exec.kind = ExecModel::Kind::kUniform;
      t.offset = from_us(r.uniform_int(0, p - 1));
      if (extras && r.bernoulli(0.4)) t.release_jitter = from_us(r.uniform_int(0, p / 4));
      if (extras && r.bernoulli(0.3)) t.nonpreemptive = from_us(r.uniform_int(0, t.exec.bcet.count() / 1000));
      s.tasks.push_back(t);
    }
    if (extras && r.bernoulli(0.5)) {
      TaskSpec isr = edf_task("isr", 1000 * r.uniform_int(1, 5), r.uniform_int(1, 20), 1, 1000000, 1);
      isr.deadline = isr.period;
      isr.exec.kind = ExecModel::Kind::kUniform;
      s.isrs.push_back(isr);
    }
    checked += test_support::check_bounded_tasks(
        s, from_us(400'000), static_cast<std::uint64_t>(n),
        [&](const CpuTaskStats& st, const TaskBound& b, const Analysis& a) {
          ASSERT_LE(st.response_max, b.wcrt) << "set " << n << " " << b.name << "\n" << task_set_json(s).dump();
          ASSERT_GE(st.response_min, b.bcrt) << "set " << n << " " << b.name << "\n" << task_set_json(s).dump();
          ASSERT_LE(st.start_max, b.sampling_latency_max) << "set " << n << " " << b.name;
          if (a.schedulable) {
            ASSERT_EQ(st.deadline_misses, 0U) << "set " << n << " " << b.name;
          }
        });
    if (HasFatalFailure()) return;
  }
  EXPECT_GT(checked, 1200U);
}

}  // namespace
