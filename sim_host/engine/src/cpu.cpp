/// @file cpu.cpp
/// @brief The CPU model: arrivals, releases, dispatching, preemption, completion, overruns.
#include "oneshot/engine/cpu.hpp"

#include <algorithm>
#include <stdexcept>

namespace oneshot::engine::cpu {

namespace {

std::uint64_t pack(std::size_t e, std::uint64_t job) { return (e << 32) | (job & 0xFFFFFFFFULL); }

}  // namespace

const char* to_string(CpuEventKind k) {
  switch (k) {
    case CpuEventKind::kRelease: return "release";
    case CpuEventKind::kStart: return "start";
    case CpuEventKind::kPreempt: return "preempt";
    case CpuEventKind::kResume: return "resume";
    case CpuEventKind::kFinish: return "finish";
    case CpuEventKind::kSkip: return "skip";
    case CpuEventKind::kAbort: return "abort";
    case CpuEventKind::kSample: return "sample";
    case CpuEventKind::kActuate: return "actuate";
  }
  return "?";
}

Cpu::Cpu(Kernel& kernel, TaskSet set) : kernel_(kernel), set_(std::move(set)) {
  if (set_.tasks.size() + set_.isrs.size() > 60000) throw std::invalid_argument("cpu: at most 60000 tasks and ISRs");
  for (std::size_t i = 0; i < set_.tasks.size(); ++i) {
    const TaskSpec& t = set_.tasks[i];
    check_point_order(t.sample_at, t.actuate_at, t.exec.bcet, t.exec.wcet, "tasks[" + std::to_string(i) + "].actuate_at");
    specs_.push_back(&t);
  }
  for (const TaskSpec& t : set_.isrs) specs_.push_back(&t);
  for (std::size_t e = 0; e < specs_.size(); ++e) {
    const std::string n = set_.streams_per_cpu ? set_.name + "/" + specs_[e]->name : specs_[e]->name;
    ent_.push_back(Entity{specs_[e], e >= set_.tasks.size(), {}, 0, SimTime{0},
                          kernel_.stream(stream_name("cpu", n, "exec")), kernel_.stream(stream_name("cpu", n, "jitter")),
                          kernel_.stream(stream_name("cpu", n, "arrival"))});
  }
  stats_.resize(specs_.size());
  h_arrive_ = kernel_.add_handler("cpu arrival", [this](std::uint64_t e) { arrive(e); });
  h_ready_ = kernel_.add_handler("cpu release", [this](std::uint64_t a) { make_ready(a); });
  h_complete_ = kernel_.add_handler("cpu completion", [this](std::uint64_t g) { complete(g); });
  h_abort_ = kernel_.add_handler("cpu abort", [this](std::uint64_t a) { abort_job(a); });
  h_dispatch_ = kernel_.add_handler("cpu dispatch", [this](std::uint64_t) { dispatch(); });
}

const std::string& Cpu::entity_name(std::size_t e) const { return specs_.at(e)->name; }

void Cpu::on_point(std::function<void(std::size_t, std::uint64_t, CpuEventKind)> f) {
  if (!on_point_) {
    h_point_ = kernel_.add_handler("cpu point", [this](std::uint64_t arg) { point(arg); });
    h_start_point_ = kernel_.add_handler("cpu start point", [this](std::uint64_t arg) { start_point(arg); });
  }
  on_point_ = std::move(f);
}

void Cpu::start_point(std::uint64_t arg) {
  // A point at the job's start (offset 0): at its start as CpuJob::start gives it, even when
  // the context switch before it was cut short (as the job's recorded sample / actuation).
  const std::size_t e = arg >> 32;
  for (Job& j : ent_[e].pending) {
    if ((j.index & 0xFFFFFFFFULL) != (arg & 0xFFFFFFFFULL)) continue;
    for (const bool act : {false, true}) {
      if ((act ? j.act_off : j.sample_off).count() != 0) continue;
      bool& told = act ? j.actuate_told : j.sample_told;
      if (told) continue;
      told = true;
      on_point_(e, j.index, act ? CpuEventKind::kActuate : CpuEventKind::kSample);
    }
    return;
  }
}

void Cpu::point(std::uint64_t arg) {
  // arg: the dispatch generation (low bits) and the kind (bit 0: actuation).
  if ((arg >> 1) != (generation_ & (~std::uint64_t{0} >> 1)) || running_ == kNone || ent_[running_].isr) return;
  account();
  Job& j = ent_[running_].pending.front();
  const bool act = (arg & 1U) != 0;
  bool& told = act ? j.actuate_told : j.sample_told;
  if (told) return;
  told = true;
  on_point_(running_, j.index, act ? CpuEventKind::kActuate : CpuEventKind::kSample);
}

void Cpu::start(SimTime end) {
  end_ = end;
  for (std::size_t e = 0; e < ent_.size(); ++e) {
    if (ent_[e].spec->external) continue;
    ent_[e].next_arrival = ent_[e].spec->offset;
    if (ent_[e].next_arrival <= end_) kernel_.schedule(ent_[e].next_arrival, EventClass::kCompute, h_arrive_, e);
  }
}

void Cpu::record(std::size_t e, std::uint64_t job, CpuEventKind k) {
  ++sched_events_;
  if (!log_enabled_) return;
  if (log_.size() >= log_limit_) {
    ++log_dropped_;
    return;
  }
  log_.push_back(CpuLogEntry{kernel_.now().count(), static_cast<std::uint32_t>(job), static_cast<std::uint16_t>(e), k});
}

void Cpu::log_point(std::size_t e, std::uint64_t job, CpuEventKind k, SimTime at) {
  if (!log_enabled_) return;
  if (log_.size() >= log_limit_) {
    ++log_dropped_;
    return;
  }
  log_.push_back(CpuLogEntry{at.count(), static_cast<std::uint32_t>(job), static_cast<std::uint16_t>(e), k});
}

void Cpu::request_dispatch(SimTime at) {
  if (at == kernel_.now()) {
    if (dispatch_at_ == at) return;
    dispatch_at_ = at;
  }
  kernel_.schedule(at, EventClass::kBus, h_dispatch_, 0);
}

void Cpu::arrive(std::size_t e) {
  Entity& en = ent_[e];
  const TaskSpec& s = *en.spec;
  const SimTime now = kernel_.now();
  Duration gap = s.period;
  if (s.sporadic && s.max_interarrival > s.period) {
    gap = from_us(en.arrival_rng.uniform_int(s.period.count() / 1000, s.max_interarrival.count() / 1000));
  }
  en.next_arrival = now + gap;
  if (en.next_arrival <= end_) kernel_.schedule(en.next_arrival, EventClass::kCompute, h_arrive_, e);
  admit(e);
}

void Cpu::release(std::size_t task) {
  if (task >= set_.tasks.size() || !set_.tasks[task].external) throw std::invalid_argument("cpu: release() of a task that is not external");
  admit(task);
}

void Cpu::admit(std::size_t e) {
  Entity& en = ent_[e];
  const TaskSpec& s = *en.spec;
  const SimTime now = kernel_.now();
  const std::uint64_t index = en.next_index++;
  if (!en.pending.empty()) {
    ++stats_[e].overruns;
    if (s.overrun == OverrunPolicy::kSkip) {
      ++stats_[e].skipped;
      record(e, index, CpuEventKind::kSkip);
      return;
    }
  }
  Job j;
  j.index = index;
  j.arrival = now;
  j.exec = s.exec.draw(en.exec_rng, index);
  j.remaining = j.exec;
  j.sample_off = s.sample_at.offset(j.exec);
  j.act_off = s.actuate_at.offset(j.exec);
  j.ready = now;
  if (s.release_jitter.count() > 0) j.ready = now + from_us(en.jitter_rng.uniform_int(0, s.release_jitter.count() / 1000));
  en.pending.push_back(j);
  if (!en.isr && s.overrun == OverrunPolicy::kAbort) {
    kernel_.schedule(now + s.deadline, EventClass::kLatch, h_abort_, pack(e, index));
  }
  if (j.ready == now) {
    make_ready(pack(e, index));
  } else {
    en.pending.back().ready = j.ready;
    kernel_.schedule(j.ready, EventClass::kCompute, h_ready_, pack(e, index));
  }
}

void Cpu::make_ready(std::uint64_t arg) {
  const std::size_t e = arg >> 32;
  // Newest first: the job made ready is nearly always the last one queued.
  for (auto it = ent_[e].pending.rbegin(); it != ent_[e].pending.rend(); ++it) {
    Job& j = *it;
    if ((j.index & 0xFFFFFFFFULL) == (arg & 0xFFFFFFFFULL)) {
      j.ready = kernel_.now();
      ++stats_[e].released;
      record(e, j.index, CpuEventKind::kRelease);
      request_dispatch(kernel_.now());
      return;
    }
  }
}

void Cpu::account() {
  if (running_ == kNone) return;
  Job& j = ent_[running_].pending.front();
  const Duration d = kernel_.now() - run_since_;
  j.remaining -= d;
  j.done += d;
  // The segment runs the rest of the dispatch's context switch, then own work: a point at own
  // offset m with own_before < m ≤ own_after is reached at work_from + (m − own_before).
  const Duration over = std::min(d, j.cs_left);
  j.cs_left -= over;
  const Duration own_before = j.own;
  j.own += d - over;
  const SimTime work_from = run_since_ + over;
  if (j.sample.count() < 0 && j.sample_off > own_before && j.sample_off <= j.own) {
    j.sample = work_from + (j.sample_off - own_before);
    log_point(running_, j.index, CpuEventKind::kSample, j.sample);
  }
  if (j.actuate.count() < 0 && j.act_off > own_before && j.act_off <= j.own) {
    j.actuate = work_from + (j.act_off - own_before);
    log_point(running_, j.index, CpuEventKind::kActuate, j.actuate);
  }
  stats_[running_].busy += d;
  run_since_ = kernel_.now();
}

void Cpu::finish_job(std::size_t e, bool aborted) {
  Entity& en = ent_[e];
  const Job j = en.pending.front();
  en.pending.pop_front();
  CpuTaskStats& st = stats_[e];
  const Duration response = kernel_.now() - j.arrival;
  if (aborted) {
    ++st.aborted;
    ++st.deadline_misses;
    record(e, j.index, CpuEventKind::kAbort);
  } else {
    if (st.finished == 0 || response < st.response_min) st.response_min = response;
    if (response > st.response_max) st.response_max = response;
    ++st.finished;
    st.response_sum_s += to_seconds(response);
    if (response > en.spec->deadline) ++st.deadline_misses;
    const Duration ls = j.sample - j.arrival, la = j.actuate - j.arrival, io = j.actuate - j.sample;
    if (st.finished == 1 || ls < st.sample_min) st.sample_min = ls;
    if (st.finished == 1 || la < st.actuate_min) st.actuate_min = la;
    if (st.finished == 1 || io < st.io_min) st.io_min = io;
    st.sample_max = std::max(st.sample_max, ls);
    st.actuate_max = std::max(st.actuate_max, la);
    st.io_max = std::max(st.io_max, io);
    record(e, j.index, CpuEventKind::kFinish);
  }
  if (on_job_) on_job_(CpuJob{e, j.index, j.arrival, j.ready, j.start, kernel_.now(), j.exec, aborted, j.sample, j.actuate});
}

void Cpu::complete(std::uint64_t generation) {
  if (generation != generation_ || running_ == kNone) return;
  account();
  const std::size_t e = running_;
  running_ = kNone;
  finish_job(e, false);
  request_dispatch(kernel_.now());
}

void Cpu::abort_job(std::uint64_t arg) {
  const std::size_t e = arg >> 32;
  Entity& en = ent_[e];
  if (en.pending.empty() || (en.pending.front().index & 0xFFFFFFFFULL) != (arg & 0xFFFFFFFFULL)) return;  // finished
  if (running_ == e) {
    account();
    running_ = kNone;
    ++generation_;
  }
  finish_job(e, true);
  request_dispatch(kernel_.now());
}

const Cpu::Job* Cpu::head_ready(std::size_t e) const {
  const Entity& en = ent_[e];
  if (en.pending.empty() || en.pending.front().ready > kernel_.now()) return nullptr;
  const Job& j = en.pending.front();
  // Not yet released: its release event is still pending at this instant (ready set, not counted).
  return &j;
}

bool Cpu::before(std::size_t a, std::size_t b) const {
  const TaskSpec& sa = *specs_[a];
  const TaskSpec& sb = *specs_[b];
  const Job& ja = ent_[a].pending.front();
  const Job& jb = ent_[b].pending.front();
  if (set_.scheduler == SchedulerKind::kEdf && !ent_[a].isr) {
    const SimTime da = ja.arrival + sa.deadline, db = jb.arrival + sb.deadline;
    if (da != db) return da < db;
  }
  if (sa.priority != sb.priority) return sa.priority < sb.priority;
  if (ja.ready != jb.ready) return ja.ready < jb.ready;
  return a < b;
}

void Cpu::dispatch() {
  dispatch_at_ = SimTime{-1};
  account();
  const SimTime now = kernel_.now();
  std::size_t best_isr = kNone, best_task = kNone, holder = kNone;
  for (std::size_t e = 0; e < ent_.size(); ++e) {
    if (head_ready(e) == nullptr) continue;
    std::size_t& best = ent_[e].isr ? best_isr : best_task;
    if (best == kNone || before(e, best)) best = e;
    const Job& j = ent_[e].pending.front();
    if (!ent_[e].isr && j.started &&
        (set_.scheduler == SchedulerKind::kFixedPriorityNonPreemptive || j.done < ent_[e].spec->nonpreemptive)) {
      holder = e;
    }
  }
  std::size_t chosen = best_isr != kNone ? best_isr : holder != kNone ? holder : best_task;
  if (best_isr == kNone && holder != kNone && best_task != holder && set_.scheduler != SchedulerKind::kFixedPriorityNonPreemptive) {
    // A better task waits for the end of the holder's non-preemptive section.
    const Job& h = ent_[holder].pending.front();
    request_dispatch(now + (ent_[holder].spec->nonpreemptive - h.done));
  }
  if (chosen == running_) return;
  if (running_ != kNone) {
    ++stats_[running_].preemptions;
    record(running_, ent_[running_].pending.front().index, CpuEventKind::kPreempt);
  }
  ++generation_;
  running_ = chosen;
  if (chosen == kNone) return;
  Job& j = ent_[chosen].pending.front();
  Duration cs{0};
  if (!ent_[chosen].isr && (last_task_ != chosen || last_task_job_ != j.index)) {
    cs = set_.context_switch;
    j.remaining += cs;
    ++context_switches_;
    last_task_ = chosen;
    last_task_job_ = j.index;
  }
  j.cs_left += cs;  // a switch cut short by an ISR is finished after it
  const bool first = !j.started;
  if (!j.started) {
    j.started = true;
    j.start = now + cs;
    CpuTaskStats& st = stats_[chosen];
    const Duration latency = j.start - j.arrival;
    if (st.started == 0 || latency < st.start_min) st.start_min = latency;
    if (latency > st.start_max) st.start_max = latency;
    ++st.started;
    record(chosen, j.index, CpuEventKind::kStart);
    if (j.sample_off.count() == 0) {
      j.sample = j.start;
      log_point(chosen, j.index, CpuEventKind::kSample, j.sample);
    }
    if (j.act_off.count() == 0) {
      j.actuate = j.start;
      log_point(chosen, j.index, CpuEventKind::kActuate, j.actuate);
    }
  } else {
    record(chosen, j.index, CpuEventKind::kResume);
  }
  run_since_ = now;
  if (on_point_ && !ent_[chosen].isr) {  // the points this dispatch reaches, before the completion
    const std::uint64_t g = (generation_ & (~std::uint64_t{0} >> 1)) << 1;
    if (first && (j.sample_off.count() == 0 || j.act_off.count() == 0)) {
      kernel_.schedule(j.start, EventClass::kCompute, h_start_point_, pack(chosen, j.index));
    }
    if (!j.sample_told && j.sample_off.count() > 0) {
      kernel_.schedule(now + j.cs_left + (j.sample_off - j.own), EventClass::kCompute, h_point_, g);
    }
    if (!j.actuate_told && j.act_off.count() > 0) {
      kernel_.schedule(now + j.cs_left + (j.act_off - j.own), EventClass::kCompute, h_point_, g | 1U);
    }
  }
  kernel_.schedule(now + j.remaining, EventClass::kCompute, h_complete_, generation_);
}

}  // namespace oneshot::engine::cpu
