/// @file cpu_test.cpp
/// @brief The CPU model against its analysis: 1000+ random task sets (utilization 0.3–0.99)
///        keep every simulated response time in [BCRT, WCRT]; synchronous release with every
///        job at its wcet reaches the WCRT (to the ns); EDF with implicit deadlines meets
///        every deadline iff U ≤ 1; textbook sets give their published response times.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <string>
#include <vector>

#include "oneshot/engine/cpu.hpp"
#include "oneshot/engine/cpu_analysis.hpp"
#include "oneshot/engine/json_fields.hpp"
#include "sim_host/engine/cpu_test_support.hpp"

namespace {

using namespace oneshot::engine;
using namespace oneshot::engine::cpu;

using test_support::simulate;
using test_support::task;

/// Periods (µs) whose hyperperiods stay small (every lcm divides 1.2 s).
const std::int64_t kPeriodsUs[] = {1000, 2000, 2500, 3000, 4000, 5000, 6000, 8000, 10000, 12000, 15000, 20000, 25000, 30000, 40000, 50000};

std::int64_t hyperperiod_us(const TaskSet& s) {
  std::int64_t h = 1;
  for (const auto* l : {&s.tasks, &s.isrs}) {
    for (const TaskSpec& t : *l) h = std::lcm(h, t.period.count() / 1000);
  }
  return h;
}

/// A random task set: n tasks, total utilization u (UUniFast), rate-monotonic priorities.
TaskSet random_set(RandomStream& r, double u, SchedulerKind sched, bool extras) {
  TaskSet s;
  s.scheduler = sched;
  const int n = static_cast<int>(r.uniform_int(2, 7));
  double left = u;
  std::vector<double> us;
  for (int i = 1; i < n; ++i) {
    const double next = left * std::pow(r.uniform01(), 1.0 / (n - i));
    us.push_back(left - next);
    left = next;
  }
  us.push_back(left);
  for (int i = 0; i < n; ++i) {
    const std::int64_t p = kPeriodsUs[r.uniform_int(0, 15)];
    const std::int64_t w = std::clamp<std::int64_t>(std::llround(us[static_cast<std::size_t>(i)] * static_cast<double>(p)), 1, p);
    const std::int64_t b = std::max<std::int64_t>(1, std::llround(static_cast<double>(w) * r.uniform(0.2, 1.0)));
    s.tasks.push_back(task("t" + std::to_string(i), p, w, b, 0));
  }
  std::stable_sort(s.tasks.begin(), s.tasks.end(), [](const TaskSpec& a, const TaskSpec& b) { return a.period < b.period; });
  for (std::size_t i = 0; i < s.tasks.size(); ++i) s.tasks[i].priority = static_cast<int>(i) + 1;
  if (extras) {
    s.context_switch = from_us(r.uniform_int(0, 5));
    for (TaskSpec& t : s.tasks) {
      t.offset = from_us(r.uniform_int(0, t.period.count() / 1000 - 1));
      if (r.bernoulli(0.3)) t.release_jitter = from_us(r.uniform_int(0, t.period.count() / 10000));
      if (sched == SchedulerKind::kFixedPriority && r.bernoulli(0.3)) t.nonpreemptive = from_us(r.uniform_int(0, t.exec.bcet.count() / 1000));
    }
    if (r.bernoulli(0.5)) {
      TaskSpec isr = task("isr", 1000 * r.uniform_int(1, 5), r.uniform_int(1, 20), 1, 1);
      isr.exec.kind = ExecModel::Kind::kUniform;
      s.isrs.push_back(isr);
    }
  }
  return s;
}

/// Every simulated response in [BCRT, WCRT] for 1200 random sets of three schedulers.
TEST(Cpu, RandomSetsStayWithinAnalysisBounds) {
  RandomStream r(7, "cpu_test/random_sets");
  std::size_t checked_sets = 0, checked_tasks = 0, exact = 0;
  for (int n = 0; n < 1200; ++n) {
    const double u = r.uniform(0.3, 0.99);
    const SchedulerKind sched = n % 3 == 0 ? SchedulerKind::kFixedPriorityNonPreemptive : SchedulerKind::kFixedPriority;
    const TaskSet s = random_set(r, u, sched, n % 2 == 1);
    const std::int64_t h = hyperperiod_us(s);
    const SimTime duration = from_us(std::min<std::int64_t>(4 * h, 2'000'000) + 60'000);
    ++checked_sets;
    checked_tasks += test_support::check_bounded_tasks(
        s, duration, static_cast<std::uint64_t>(n), [&](const CpuTaskStats& st, const TaskBound& b, const Analysis&) {
          ASSERT_LE(st.response_max, b.wcrt) << "set " << n << " task " << b.name << " U " << u;
          ASSERT_GE(st.response_min, b.bcrt) << "set " << n << " task " << b.name << " U " << u << "\n"
                                             << oneshot::engine::cpu::task_set_json(s).dump();
          ASSERT_LE(st.start_max, b.sampling_latency_max) << "set " << n << " task " << b.name;
          if (st.response_max == b.wcrt) ++exact;
        });
    if (HasFatalFailure()) return;
  }
  EXPECT_EQ(checked_sets, 1200U);
  EXPECT_GT(checked_tasks, 3000U);
  RecordProperty("tasks_checked", static_cast<int>(checked_tasks));
  RecordProperty("wcrt_reached_exactly", static_cast<int>(exact));
}

/// A harsher mix than above, overloads included (U 0.2–1.3): equal priorities, deadlines
/// from T/2 to 2T, release jitter up to 2T, sporadic tasks and ISRs, up to two ISRs with
/// jitter, non-preemptive sections, switches up to 10 µs, all three schedulers. Bounded
/// tasks stay in [BCRT, WCRT] (EDF: a set found schedulable misses nothing). Found two bugs:
/// EDF with J + C > D, and the non-preemptive analysis stopping before the busy period's end.
TEST(Cpu, StressedSetsStayWithinAnalysisBounds) {
  RandomStream r(17, "cpu_test/stress");
  const std::int64_t periods[] = {1000, 2000, 2500, 3000, 4000, 5000, 6000, 8000, 10000, 12000, 15000, 20000};
  std::size_t checked = 0;
  for (int n = 0; n < 1500; ++n) {
    TaskSet s;
    const auto sk = r.uniform_int(0, 2);
    s.scheduler = sk == 0 ? SchedulerKind::kFixedPriority : sk == 1 ? SchedulerKind::kFixedPriorityNonPreemptive : SchedulerKind::kEdf;
    s.context_switch = from_us(r.uniform_int(0, 10));
    const std::int64_t nt = r.uniform_int(1, 6);
    const double u = r.uniform(0.2, 1.3);
    for (std::int64_t i = 0; i < nt; ++i) {
      const auto [p, w] = test_support::random_share(r, periods, u, nt, 1);
      TaskSpec t = task("t" + std::to_string(i), p, w, std::max<std::int64_t>(1, std::llround(static_cast<double>(w) * r.uniform(0.1, 1.0))),
                        static_cast<int>(r.uniform_int(1, 4)));
      t.exec.kind = ExecModel::Kind::kUniform;
      t.deadline = from_us(std::max<std::int64_t>(1, std::llround(static_cast<double>(p) * r.uniform(0.5, 2.0))));
      t.offset = from_us(r.uniform_int(0, p));
      if (r.bernoulli(0.3)) t.release_jitter = from_us(r.uniform_int(0, 2 * p));
      if (r.bernoulli(0.3)) t.nonpreemptive = from_us(r.uniform_int(0, t.exec.bcet.count() / 1000));
      if (r.bernoulli(0.3)) {
        t.sporadic = true;
        t.max_interarrival = from_us(p * r.uniform_int(1, 3));
      }
      s.tasks.push_back(t);
    }
    for (std::int64_t i = 0, ni = r.uniform_int(0, 2); i < ni; ++i) {
      const std::int64_t p = 1000 * r.uniform_int(1, 7);
      TaskSpec t = task("i" + std::to_string(i), p, r.uniform_int(1, 30), 1, static_cast<int>(r.uniform_int(1, 2)));
      t.exec.kind = ExecModel::Kind::kUniform;
      t.offset = from_us(r.uniform_int(0, p));
      if (r.bernoulli(0.3)) t.release_jitter = from_us(r.uniform_int(0, p / 2));
      if (r.bernoulli(0.3)) {
        t.sporadic = true;
        t.max_interarrival = from_us(2 * p);
      }
      s.isrs.push_back(t);
    }
    const Analysis a = analyze(s);
    const std::vector<CpuTaskStats> st = simulate(s, from_us(600'000), static_cast<std::uint64_t>(n));
    const bool edf = s.scheduler == SchedulerKind::kEdf;
    for (std::size_t e = 0; e < st.size(); ++e) {
      const bool isr = e >= s.tasks.size();
      const TaskBound& b = isr ? a.isrs[e - s.tasks.size()] : a.tasks[e];
      if (!b.bounded || st[e].finished == 0) continue;
      ++checked;
      ASSERT_GE(st[e].response_min, b.bcrt) << "set " << n << " " << b.name << "\n" << task_set_json(s).dump();
      if (edf && !isr && a.schedulable) {
        ASSERT_EQ(st[e].deadline_misses, 0U) << "set " << n << " " << b.name << "\n" << task_set_json(s).dump();
      }
      ASSERT_LE(st[e].response_max, b.wcrt) << "set " << n << " " << b.name << "\n" << task_set_json(s).dump();
      if (!isr) {
        ASSERT_LE(st[e].start_max, b.sampling_latency_max) << "set " << n << " " << b.name;
      }
    }
  }
  EXPECT_GT(checked, 4000U);
}

/// Synchronous release, every job at its wcet, no context switch: the simulated worst case
/// equals the WCRT (preemptive fixed priority, the critical instant; ISRs included).
TEST(Cpu, SynchronousWcetReachesWcrt) {
  RandomStream r(11, "cpu_test/critical_instant");
  std::size_t reached = 0, total = 0;
  for (int n = 0; n < 300; ++n) {
    TaskSet s = random_set(r, r.uniform(0.3, 0.99), SchedulerKind::kFixedPriority, false);
    for (TaskSpec& t : s.tasks) {
      t.exec.bcet = t.exec.wcet;
      t.exec.kind = ExecModel::Kind::kConstant;
    }
    if (n % 2 == 0) {
      const std::int64_t cost = r.uniform_int(1, 30);
      s.isrs.push_back(task("isr", 1000 * r.uniform_int(1, 5), cost, cost, 1));
    }
    const Analysis a = analyze(s);
    std::int64_t busy = 0;
    for (const TaskBound& b : a.tasks) busy = std::max(busy, b.bounded ? b.wcrt.count() / 1000 : 0);
    const SimTime duration = from_us(std::min<std::int64_t>(hyperperiod_us(s), 3'000'000) + busy);
    const std::vector<CpuTaskStats> st = simulate(s, duration, 1);
    for (std::size_t i = 0; i < s.tasks.size(); ++i) {
      if (!a.tasks[i].bounded || a.tasks[i].wcrt > duration) continue;
      ++total;
      EXPECT_LE((a.tasks[i].wcrt - st[i].response_max).count(), 1000) << "set " << n << " task " << i;  // one µs tick
      EXPECT_LE(st[i].response_max, a.tasks[i].wcrt);
      if (st[i].response_max == a.tasks[i].wcrt) ++reached;
    }
  }
  EXPECT_EQ(reached, total);
  EXPECT_GT(total, 700U);
}

/// EDF with implicit deadlines: no deadline miss iff U ≤ 1 (analysis and simulation agree).
TEST(Cpu, EdfImplicitDeadlinesSchedulableIffUtilizationAtMostOne) {
  RandomStream r(13, "cpu_test/edf");
  std::size_t ok = 0, overloaded = 0;
  for (int n = 0; n < 400; ++n) {
    const double u = n % 4 == 3 ? r.uniform(1.01, 1.2) : r.uniform(0.3, 1.0);
    TaskSet s = random_set(r, u, SchedulerKind::kEdf, false);
    for (TaskSpec& t : s.tasks) t.exec.bcet = t.exec.wcet;  // every job at its wcet: U is the real load
    const double real_u = s.utilization();
    const Analysis a = analyze(s);
    const std::int64_t h = hyperperiod_us(s);
    const std::vector<CpuTaskStats> st = simulate(s, from_us(std::min<std::int64_t>(2 * h, 4'000'000)), 3);
    std::uint64_t misses = 0;
    for (const CpuTaskStats& x : st) misses += x.deadline_misses;
    EXPECT_EQ(a.schedulable, real_u <= 1.0) << "set " << n << " U " << real_u;
    if (real_u <= 1.0) {
      EXPECT_EQ(misses, 0U) << "set " << n << " U " << real_u;
      ++ok;
    } else if (2 * h <= 4'000'000) {
      EXPECT_GT(misses, 0U) << "set " << n << " U " << real_u;
      ++overloaded;
    }
  }
  EXPECT_GT(ok, 250U);
  EXPECT_GT(overloaded, 50U);
}

/// Textbook sets with published response times, analysis and simulation (synchronous release):
/// Buttazzo, Hard Real-Time Computing Systems (3rd ed.), C = (1, 2, 3), T = (4, 6, 10) gives
/// R = (1, 3, 10) (Redell–Sanfridson by hand: BCRT = 3 for τ3); Burns & Wellings, Real-Time
/// Systems and Programming Languages, (C, T) = (3, 7), (3, 12), (5, 20) gives R = (3, 6, 20).
TEST(Cpu, TextbookSets) {
  struct Case {
    const char* source;
    std::vector<TaskSpec> tasks;
    std::vector<std::int64_t> wcrt_us;
  };
  const std::vector<Case> cases = {
      {"Buttazzo", {task("t1", 4, 1, 1, 1), task("t2", 6, 2, 2, 2), task("t3", 10, 3, 3, 3)}, {1, 3, 10}},
      {"Burns & Wellings", {task("a", 7, 3, 3, 1), task("b", 12, 3, 3, 2), task("c", 20, 5, 5, 3)}, {3, 6, 20}}};
  for (const Case& c : cases) {
    TaskSet s;
    s.tasks = c.tasks;
    const Analysis a = analyze(s);
    EXPECT_TRUE(a.schedulable) << c.source;
    for (std::size_t i = 0; i < c.wcrt_us.size(); ++i) EXPECT_EQ(a.tasks[i].wcrt, from_us(c.wcrt_us[i])) << c.source << " " << i;
    EXPECT_EQ(simulate(s, from_us(420), 1)[2].response_max, from_us(c.wcrt_us[2])) << c.source;
    if (std::string(c.source) == "Buttazzo") {
      EXPECT_EQ(a.tasks[2].bcrt, from_us(3));
    }
  }
}

/// (C, T) = (1, 3), (1, 4), (2, 5), U = 0.983: rate monotonic misses with the third task
/// (R = 6 > 5, reported), EDF meets every deadline (Liu & Layland).
TEST(Cpu, UnschedulableUnderRmScheduledByEdf) {
  TaskSet s;
  s.tasks = {task("x", 3, 1, 1, 1), task("y", 4, 1, 1, 2), task("z", 5, 2, 2, 3)};
  const Analysis rm = analyze(s);
  EXPECT_FALSE(rm.schedulable);
  EXPECT_EQ(rm.first_miss, "z");
  EXPECT_EQ(rm.tasks[2].wcrt, from_us(6));
  EXPECT_GT(simulate(s, from_us(600), 1)[2].deadline_misses, 0U);
  s.scheduler = SchedulerKind::kEdf;
  EXPECT_TRUE(analyze(s).schedulable);
  for (const CpuTaskStats& x : simulate(s, from_us(600), 1)) EXPECT_EQ(x.deadline_misses, 0U);
}

/// Overrun policies: a task that cannot fit (wcet 6 of 10 below a 5-of-10 task) skips,
/// aborts or queues, each counted.
TEST(Cpu, OverrunPoliciesAreCounted) {
  for (OverrunPolicy p : {OverrunPolicy::kSkip, OverrunPolicy::kAbort, OverrunPolicy::kContinue}) {
    TaskSet s;
    s.tasks = {task("hi", 10, 5, 5, 1), task("lo", 10, 6, 6, 2)};
    s.tasks[1].overrun = p;
    const auto st = simulate(s, from_us(1000), 1);
    EXPECT_GT(st[1].deadline_misses, 0U) << to_string(p);
    if (p == OverrunPolicy::kSkip) {
      EXPECT_GT(st[1].skipped, 0U);
    }
    if (p == OverrunPolicy::kAbort) {
      EXPECT_EQ(st[1].finished, 0U);  // 6 of 10 never fits beside 5 of 10: every job aborted
      EXPECT_GE(st[1].aborted + 1, st[1].released);  // the last one may still run at the end
    }
    if (p == OverrunPolicy::kContinue) {
      EXPECT_GT(st[1].overruns, 0U);
    }
    EXPECT_EQ(st[0].deadline_misses, 0U);
  }
}

/// The log holds every release, start, sample, preemption, resume, actuation and finish, in time order
/// (default points: the sample at the start, the actuation at the end).
TEST(Cpu, LogRecordsPreemptionAndResume) {
  TaskSet s;
  s.tasks = {task("hi", 4, 1, 1, 1), task("lo", 8, 5, 5, 2)};
  Kernel k(1);
  Cpu cpu(k, s);
  cpu.enable_log(1000);
  cpu.start(from_us(7));
  k.run_until(from_us(100));
  std::string seq;
  for (const CpuLogEntry& e : cpu.log()) seq += std::string(to_string(e.kind)) + ":" + cpu.entity_name(e.entity) + "@" + std::to_string(e.t_ns / 1000) + " ";
  EXPECT_EQ(seq,
            "release:hi@0 release:lo@0 start:hi@0 sample:hi@0 actuate:hi@1 finish:hi@1 start:lo@1 sample:lo@1 release:hi@4 "
            "preempt:lo@4 start:hi@4 sample:hi@4 actuate:hi@5 finish:hi@5 resume:lo@5 actuate:lo@7 finish:lo@7 ");
}

/// An external task (a node's job) arrives only when released: hi (T 4, C 1) above ext (C 2):
/// released at 0 and 4 it waits for hi's job (response 1 + 2), at 9 it runs at once (2).
TEST(Cpu, ExternalTaskArrivesOnlyWhenReleased) {
  TaskSet s;
  s.tasks = {task("hi", 4, 1, 1, 1), task("ext", 10, 2, 2, 2)};
  s.tasks[1].external = true;
  s.tasks[1].sporadic = true;
  Kernel k(1);
  Cpu cpu(k, s);
  const HandlerId rel = k.add_handler("release", [&](std::uint64_t) { cpu.release(1); });
  for (std::int64_t t : {0, 4, 9}) k.schedule(SimTime{from_us(t)}, EventClass::kEnvironment, rel);
  std::vector<std::int64_t> responses;
  cpu.on_job([&](const CpuJob& j) {
    if (j.entity == 1) responses.push_back((j.finish - j.arrival).count() / 1000);
  });
  cpu.start(from_us(40));
  k.run_until(from_us(50));
  EXPECT_EQ(responses, (std::vector<std::int64_t>{3, 3, 2}));
  EXPECT_EQ(cpu.stats()[1].released, 3U);
  EXPECT_EQ(cpu.stats()[0].released, 11U);  // hi: 0, 4, …, 40
  EXPECT_THROW(cpu.release(0), std::invalid_argument);  // hi is not external
}

}  // namespace
