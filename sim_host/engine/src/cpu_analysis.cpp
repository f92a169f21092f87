/// @file cpu_analysis.cpp
/// @brief Response-time analysis and the EDF demand test (equations in cpu_analysis.hpp).
#include "oneshot/engine/cpu_analysis.hpp"

#include <algorithm>
#include <cstdint>
#include <numeric>

namespace oneshot::engine::cpu {

namespace {

using I = std::int64_t;

/// Most jobs of a busy period examined before the analysis calls it unbounded.
constexpr I kMaxJobs = 1'000'000;

I ceil_div(I a, I b) { return a <= 0 ? -((-a) / b) : (a + b - 1) / b; }
I floor_div(I a, I b) { return a >= 0 ? a / b : -((-a + b - 1) / b); }

/// One interfering entity in ns.
struct Load {
  I c = 0, cb = 0, t = 0, j = 0;
  bool periodic = true;
};

/// The analysis' limit: a busy period beyond 10^4 largest periods (or 2^50 ns) is unbounded.
I horizon(const TaskSet& s) {
  I tmax = 1;
  for (const auto* l : {&s.tasks, &s.isrs}) {
    for (const TaskSpec& t : *l) tmax = std::max(tmax, std::max(t.period.count(), t.deadline.count()));
  }
  return std::min<I>(tmax * 10'000, I{1} << 50);
}

/// Smallest w ≥ w0 with w = base + Σ ⌈(w + J)/T⌉ C over `loads` (−1 beyond `limit`).
I fixed_point(I base, I w0, const std::vector<Load>& loads, I limit) {
  I w = std::max(w0, base);
  for (;;) {
    I next = base;
    for (const Load& l : loads) next += ceil_div(w + l.j, l.t) * l.c;
    if (next == w) return w;
    if (next > limit) return -1;
    w = std::max(next, w);
  }
}

/// Redell–Sanfridson: from r = WCRT downward to the fixed point of
/// r = own + Σ max(0, ⌈(r − J − T)/T⌉) C^b over the periodic loads.
I best_case(I own, I wcrt, const std::vector<Load>& loads) {
  I r = std::max(wcrt, own);
  for (int it = 0; it < 1'000'000; ++it) {
    I next = own;
    for (const Load& l : loads) {
      if (l.periodic) next += std::max<I>(0, ceil_div(r - l.j - l.t, l.t)) * l.cb;
    }
    if (next >= r) return r;
    r = next;
  }
  return own;
}

Load load_of(const TaskSpec& t, I extra) {
  return Load{t.exec.wcet.count() + extra, t.exec.bcet.count(), t.period.count(), t.release_jitter.count(), !t.sporadic};
}

/// Latency bounds of a point at own offset m(e) (cpu_job_point.hpp): it is reached after the
/// first switch and m(C^b) of own work, and at least C^b − m(C^b) of own work before the end:
///     [cs + m(C^b), WCRT − (C^b − m(C^b))]   (the end: [BCRT, WCRT]; the start: [cs, WCRT − C^b])
/// input-output latency: [min_e (m_a(e) − m_s(e)), max actuation − min sample latency].
void finish_bound(TaskBound& b, const TaskSpec& t, I cs) {
  b.schedulable = b.bounded && b.wcrt <= t.deadline;
  const Duration bc = t.exec.bcet;
  auto lo = [&](const JobPoint& p) { return p.kind == JobPoint::Kind::kEnd ? b.bcrt : Duration{cs} + p.offset(bc); };
  auto hi = [&](const JobPoint& p) { return b.bounded ? b.wcrt - (bc - p.offset(bc)) : Duration{0}; };
  b.sampling_latency_min = lo(t.sample_at);
  b.sampling_latency_max = hi(t.sample_at);
  b.actuation_latency_min = lo(t.actuate_at);
  b.actuation_latency_max = hi(t.actuate_at);
  const bool floors = t.sample_at.kind == JobPoint::Kind::kFraction || t.actuate_at.kind == JobPoint::Kind::kFraction;
  b.io_latency_min = std::max(Duration{0}, min_work_between(t.sample_at, t.actuate_at, bc, t.exec.wcet) - Duration{floors ? 2 : 0});
  b.io_latency_max = b.bounded ? b.actuation_latency_max - b.sampling_latency_min : Duration{0};
}

/// ISRs: preemptive fixed priority among themselves, no context switch, no blocking.
TaskBound isr_bound(const TaskSet& s, std::size_t k, I limit) {
  const TaskSpec& t = s.isrs[k];
  std::vector<Load> hp;
  for (std::size_t o = 0; o < s.isrs.size(); ++o) {
    if (o != k && s.isrs[o].priority <= t.priority) hp.push_back(load_of(s.isrs[o], 0));
  }
  TaskBound b;
  b.name = t.name;
  b.isr = true;
  b.wcrt_method = "fixed priority among ISRs";
  I best = 0;
  for (I q = 0;; ++q) {
    const I w = fixed_point((q + 1) * t.exec.wcet.count(), 0, hp, limit);
    if (w < 0 || q >= kMaxJobs) {
      b.bounded = false;
      break;
    }
    best = std::max(best, w - q * t.period.count() + t.release_jitter.count());
    b.jobs_examined = static_cast<std::size_t>(q + 1);
    if (w <= (q + 1) * t.period.count() - t.release_jitter.count()) break;
  }
  b.wcrt = Duration{best};
  b.bcrt = Duration{best_case(t.exec.bcet.count(), best, hp)};
  finish_bound(b, t, 0);
  return b;
}

TaskBound fp_bound(const TaskSet& s, std::size_t i, I limit) {
  const TaskSpec& t = s.tasks[i];
  const I cs = s.context_switch.count();
  const bool np = s.scheduler == SchedulerKind::kFixedPriorityNonPreemptive;
  std::vector<Load> hp, isr;
  I blocking = 0;
  for (std::size_t o = 0; o < s.tasks.size(); ++o) {
    if (o == i) continue;
    const TaskSpec& u = s.tasks[o];
    if (u.priority <= t.priority) {
      hp.push_back(load_of(u, np ? cs : 2 * cs));
    } else {
      blocking = std::max(blocking, np ? u.exec.wcet.count() + cs : u.nonpreemptive.count());
    }
  }
  for (const TaskSpec& k : s.isrs) isr.push_back(load_of(k, 0));
  TaskBound b;
  b.name = t.name;
  b.blocking = Duration{blocking};
  b.wcrt_method = np ? "fixed priority non-preemptive (start-time busy-period analysis)"
                     : "fixed priority preemptive (Joseph-Pandya/Audsley, level-i busy period)";
  const I c = t.exec.wcet.count() + cs;
  const I period = t.period.count();
  const I jitter = t.release_jitter.count();
  I worst = 0;
  std::vector<Load> all = hp;  // hp tasks and ISRs
  all.insert(all.end(), isr.begin(), isr.end());
  // Level-i utilization above 1: the busy period never closes (checked first: the iterations
  // below would only creep towards the limit).
  double u_hep = static_cast<double>(c) / static_cast<double>(period);
  for (const Load& l : all) u_hep += static_cast<double>(l.c) / static_cast<double>(l.t);
  // Non-preemptive: the jobs of the level-i busy period t = B + Σ_{hep, ISR} ⌈(t + J)/T⌉ C'
  // (Davis et al. 2007: the preemptive stopping rule below is optimistic here).
  I jobs_np = 0;
  if (np && u_hep <= 1.0) {
    std::vector<Load> with_own = all;
    with_own.push_back(Load{c, 0, period, jitter, true});
    const I busy = fixed_point(blocking, c, with_own, limit);
    jobs_np = busy < 0 ? -1 : ceil_div(busy + jitter, period);  // −1: the busy period does not close
  }
  std::vector<Load> all_np = all;  // ⌊x/T⌋ + 1 = ⌈(x + 1)/T⌉ for integer ns
  for (Load& l : all_np) l.j += 1;
  // w(q) and s(q) grow with q: each fixed point starts from the previous one.
  I prev_f = 0, prev_start = 0;
  for (I q = 0;; ++q) {
    I f = -1;
    if (u_hep > 1.0 || (np && jobs_np < 0) || q >= kMaxJobs) {
      f = -1;
    } else if (!np) {
      f = fixed_point(blocking + (q + 1) * c, prev_f, all, limit);
    } else {
      // s = B + qC' + Σ (⌊(s + J)/T⌋ + 1) C' over hp tasks and ISRs; then the own job and the
      // ISRs until it ends.
      const I start = fixed_point(blocking + q * c, prev_start, all_np, limit);
      if (start >= 0) {
        I hp_part = blocking + q * c;
        for (const Load& l : hp) hp_part += ceil_div(start + l.j + 1, l.t) * l.c;
        f = fixed_point(hp_part + c, start + c, isr, limit);
        prev_start = start;
      }
    }
    if (f < 0) {
      b.bounded = false;
      break;
    }
    prev_f = f;
    worst = std::max(worst, f - q * period + jitter);
    b.jobs_examined = static_cast<std::size_t>(q + 1);
    if (np ? q + 1 >= jobs_np : f <= (q + 1) * period - jitter) break;
  }
  b.wcrt = Duration{worst};
  std::vector<Load> best_loads = isr;
  // Equal priorities do not preempt: only strictly higher tasks count in the best case.
  if (!np) {
    best_loads = isr;
    for (const TaskSpec& u : s.tasks) {
      if (u.priority < t.priority) best_loads.push_back(load_of(u, 0));
    }
  }
  b.bcrt = Duration{best_case(t.exec.bcet.count() + cs, b.bounded ? worst : t.exec.bcet.count() + cs, best_loads)};
  finish_bound(b, t, cs);
  return b;
}

/// EDF worst-case response time of task i (Spuri 1996, release jitter; equations in
/// cpu_analysis.hpp): the analysed job arrives at x − J_i (released at x) in a busy period
/// where every other task is released at 0 after its largest jitter and then as fast as it
/// may; only jobs with absolute deadline ≤ d = x − J_i + D_i compete. −1: unbounded.
I edf_wcrt(const TaskSet& s, std::size_t i, I limit, TaskBound& b) {
  const I cs = s.context_switch.count();
  const TaskSpec& t = s.tasks[i];
  const I ci = t.exec.wcet.count() + cs, ti = t.period.count(), ji = t.release_jitter.count(), di = t.deadline.count();
  std::vector<Load> others, isr;
  std::vector<I> dl;
  I blocking = 0;
  for (std::size_t o = 0; o < s.tasks.size(); ++o) {
    if (o == i) continue;
    others.push_back(load_of(s.tasks[o], 2 * cs));
    dl.push_back(s.tasks[o].deadline.count());
    blocking = std::max(blocking, s.tasks[o].nonpreemptive.count());  // safe: any other task's section
  }
  for (const TaskSpec& k : s.isrs) isr.push_back(load_of(k, 0));
  b.blocking = Duration{blocking};
  // L = B + Σ_{all} ⌈(L + J)/T⌉ C': the longest busy period (jitter-synchronous release).
  std::vector<Load> all = others;
  all.push_back(Load{ci, 0, ti, ji, true});
  all.insert(all.end(), isr.begin(), isr.end());
  I sum_c = blocking;
  for (const Load& l : all) sum_c += l.c;
  const I busy = fixed_point(blocking, sum_c, all, limit);
  if (busy < 0) return -1;
  // Candidates x ∈ [0, L): x = k T_i, and x = k T_j + D_j − J_j − D_i + J_i (where the count
  // of j's jobs with deadline ≤ d steps); w(x) − x is largest at these left ends.
  std::vector<I> xs;
  for (I x = 0; x < busy; x += ti) xs.push_back(x);
  for (std::size_t o = 0; o < others.size(); ++o) {
    const I first = dl[o] - others[o].j - di + ji;
    for (I k = first < 0 ? ceil_div(-first, others[o].t) : 0; first + k * others[o].t < busy; ++k) {
      xs.push_back(first + k * others[o].t);
      if (static_cast<I>(xs.size()) > kMaxJobs) return -1;
    }
  }
  std::sort(xs.begin(), xs.end());
  xs.erase(std::unique(xs.begin(), xs.end()), xs.end());
  I worst = 0;
  std::vector<I> cap(others.size());
  for (const I x : xs) {
    // w = B + (1 + ⌊x/T_i⌋) C'_i + Σ_j min(⌈(w + J_j)/T_j⌉, (1 + ⌊(d + J_j − D_j)/T_j⌋)⁺) C'_j
    //       + Σ_ISR ⌈(w + J_k)/T_k⌉ C_k
    const I d = x - ji + di;
    for (std::size_t o = 0; o < others.size(); ++o) cap[o] = std::max<I>(0, 1 + floor_div(d + others[o].j - dl[o], others[o].t));
    const I base = blocking + (1 + x / ti) * ci;
    I w = base;
    for (;;) {
      I next = base;
      for (std::size_t o = 0; o < others.size(); ++o) {
        next += std::min(ceil_div(w + others[o].j, others[o].t), cap[o]) * others[o].c;
      }
      for (const Load& l : isr) next += ceil_div(w + l.j, l.t) * l.c;
      if (next <= w) break;
      w = next;
    }
    worst = std::max(worst, w - x + ji);
  }
  b.jobs_examined = xs.size();
  return worst;
}

void edf_analysis(const TaskSet& s, Analysis& a, I limit) {
  const I cs = s.context_switch.count();
  std::vector<Load> all;
  bool simple = s.isrs.empty();
  for (const TaskSpec& t : s.tasks) {
    all.push_back(load_of(t, 2 * cs));
    simple = simple && t.deadline >= t.period && t.release_jitter.count() == 0 && t.nonpreemptive.count() == 0;
  }
  for (const TaskSpec& k : s.isrs) all.push_back(load_of(k, 0));
  double u = 0;
  for (const Load& l : all) u += static_cast<double>(l.c) / static_cast<double>(l.t);
  std::string miss;
  std::string reason;
  for (const TaskSpec& t : s.tasks) {
    // A job released J late still needs C: J + C' > D misses whatever the others do.
    if (miss.empty() && t.release_jitter.count() + t.exec.wcet.count() + cs > t.deadline.count()) {
      miss = t.name;
      reason = "release jitter plus execution time exceed the deadline";
    }
  }
  if (!miss.empty()) {
    // already decided
  } else if (simple && cs == 0) {
    if (u > 1.0 + 1e-12) {
      miss = s.tasks.front().name;
      reason = "EDF with implicit deadlines: utilization above 1";
    }
  } else if (u > 1.0 + 1e-12) {
    miss = s.tasks.front().name;
    reason = "utilization above 1";
  } else {
    I sum_c = 0;
    for (const Load& l : all) sum_c += l.c;
    const I busy = fixed_point(sum_c, 0, all, limit);
    a.edf_horizon = Duration{busy < 0 ? limit : busy};
    // Absolute deadlines t = k T_i + D_i − J_i ≤ L, visited in increasing order.
    std::vector<I> next(s.tasks.size());
    for (std::size_t i = 0; i < s.tasks.size(); ++i) next[i] = s.tasks[i].deadline.count() - s.tasks[i].release_jitter.count();
    const I horizon_ns = a.edf_horizon.count();
    for (std::size_t points = 0; points < 10'000'000; ++points) {
      std::size_t who = 0;
      for (std::size_t i = 1; i < next.size(); ++i) {
        if (next[i] < next[who]) who = i;
      }
      const I t = next[who];
      if (t > horizon_ns) break;
      if (t > 0) {
        I demand = 0, np = 0;
        for (std::size_t i = 0; i < s.tasks.size(); ++i) {
          const TaskSpec& x = s.tasks[i];
          demand += std::max<I>(0, floor_div(t + x.release_jitter.count() - x.deadline.count(), x.period.count()) + 1) *
                    (x.exec.wcet.count() + 2 * cs);
          if (x.deadline.count() > t) np = std::max(np, x.nonpreemptive.count());
        }
        for (const TaskSpec& k : s.isrs) demand += ceil_div(t + k.release_jitter.count(), k.period.count()) * k.exec.wcet.count();
        a.edf_points = points + 1;
        if (demand + np > t) {
          miss = s.tasks[who].name;
          reason = "processor demand " + std::to_string(demand + np) + " ns exceeds the interval " + std::to_string(t) +
                   " ns (deadline of a job of " + miss + ")";
          break;
        }
      }
      next[who] += s.tasks[who].period.count();
    }
  }
  for (std::size_t i = 0; i < s.tasks.size(); ++i) {
    const TaskSpec& t = s.tasks[i];
    TaskBound b;
    b.name = t.name;
    b.wcrt_method = "EDF response-time analysis (Spuri 1996, release jitter, candidate arrival offsets)";
    const I w = u > 1.0 + 1e-12 ? -1 : edf_wcrt(s, i, limit, b);
    b.bounded = w >= 0;
    b.wcrt = Duration{b.bounded ? w : 0};
    std::vector<Load> isr;
    for (const TaskSpec& k : s.isrs) isr.push_back(load_of(k, 0));
    b.bcrt = Duration{best_case(t.exec.bcet.count() + cs, b.bounded ? b.wcrt.count() : t.exec.bcet.count() + cs, isr)};
    finish_bound(b, t, cs);
    a.tasks.push_back(b);
  }
  if (!miss.empty()) {
    a.first_miss = miss;
    a.reason = reason;
  }
}

}  // namespace

Analysis analyze(const TaskSet& set) {
  Analysis a;
  a.utilization = set.utilization();
  const I limit = horizon(set);
  for (std::size_t k = 0; k < set.isrs.size(); ++k) a.isrs.push_back(isr_bound(set, k, limit));
  if (set.scheduler == SchedulerKind::kEdf) {
    edf_analysis(set, a, limit);
  } else {
    for (std::size_t i = 0; i < set.tasks.size(); ++i) a.tasks.push_back(fp_bound(set, i, limit));
  }
  for (const auto* l : {&a.isrs, &a.tasks}) {
    for (const TaskBound& b : *l) {
      if (!b.schedulable && a.first_miss.empty()) {
        a.first_miss = b.name;
        a.reason = b.bounded ? "worst-case response time exceeds the deadline" : "busy period does not close (overload)";
      }
    }
  }
  a.schedulable = a.first_miss.empty();
  return a;
}

nlohmann::json analysis_json(const TaskSet& set, const Analysis& a) {
  auto one = [](const TaskBound& b, const TaskSpec& t) {
    auto us = [](Duration d) { return static_cast<double>(d.count()) * 1e-3; };
    nlohmann::json j = {{"name", b.name},
                        {"schedulable", b.schedulable},
                        {"wcrt_us", b.bounded ? nlohmann::json(us(b.wcrt)) : nlohmann::json(nullptr)},
                        {"bcrt_us", us(b.bcrt)},
                        {"deadline_us", us(t.deadline)},
                        {"blocking_us", us(b.blocking)},
                        {"jobs_examined", b.jobs_examined},
                        {"wcrt_method", b.wcrt_method},
                        {"sampling_latency_min_us", us(b.sampling_latency_min)},
                        {"sampling_latency_max_us", b.bounded ? nlohmann::json(us(b.sampling_latency_max)) : nlohmann::json(nullptr)},
                        {"sampling_jitter_bound_us",
                         b.bounded ? nlohmann::json(us(b.sampling_latency_max - b.sampling_latency_min)) : nlohmann::json(nullptr)},
                        {"jitter_bound_us", b.bounded ? nlohmann::json(us(b.wcrt - b.bcrt)) : nlohmann::json(nullptr)},
                        {"actuation_latency_min_us", us(b.actuation_latency_min)},
                        {"actuation_latency_max_us", b.bounded ? nlohmann::json(us(b.actuation_latency_max)) : nlohmann::json(nullptr)},
                        {"actuation_jitter_bound_us",
                         b.bounded ? nlohmann::json(us(b.actuation_latency_max - b.actuation_latency_min)) : nlohmann::json(nullptr)},
                        {"io_latency_min_us", us(b.io_latency_min)},
                        {"io_latency_max_us", b.bounded ? nlohmann::json(us(b.io_latency_max)) : nlohmann::json(nullptr)},
                        {"io_jitter_bound_us",
                         b.bounded ? nlohmann::json(us(b.io_latency_max - b.io_latency_min)) : nlohmann::json(nullptr)}};
    if (!b.isr) {
      j["sample_at"] = job_point_json(t.sample_at);
      j["actuate_at"] = job_point_json(t.actuate_at);
    }
    return j;
  };
  nlohmann::json j = {{"schedulable", a.schedulable},
                      {"scheduler", to_string(set.scheduler)},
                      {"utilization", a.utilization},
                      {"tasks", nlohmann::json::array()},
                      {"isrs", nlohmann::json::array()}};
  for (std::size_t i = 0; i < a.tasks.size(); ++i) j["tasks"].push_back(one(a.tasks[i], set.tasks[i]));
  for (std::size_t i = 0; i < a.isrs.size(); ++i) j["isrs"].push_back(one(a.isrs[i], set.isrs[i]));
  if (!a.schedulable) {
    j["first_miss"] = a.first_miss;
    j["reason"] = a.reason;
  }
  if (set.scheduler == SchedulerKind::kEdf) {
    j["edf_horizon_us"] = static_cast<double>(a.edf_horizon.count()) * 1e-3;
    j["edf_points_checked"] = a.edf_points;
  }
  return j;
}

}  // namespace oneshot::engine::cpu
