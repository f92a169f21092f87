/// @file study_cpu.cpp
/// @brief The CPUs of a study file: task sets with node jobs, their analysis, the ncs
///        node jobs mapped onto the loop (see study_cpu.hpp).
#include "study_cpu.hpp"

#include <algorithm>
#include <cstdio>
#include <memory>
#include <optional>
#include <sstream>

#include <nlohmann/json.hpp>

#include "ncs_cpu.hpp"
#include "ncs_model.hpp"
#include "study_fields.hpp"

namespace oneshot::study {
namespace {

using engine::Duration;
using engine::InputError;
using nlohmann::json;

double us(Duration d) { return static_cast<double>(d.count()) * 1e-3; }

/// Spread (max − min) of link `l`'s delay under scenario `s`; nullopt without an upper bound
/// or on a CAN bus.
std::optional<Duration> link_spread(const engine::StudyFile& f, const engine::LinkSpec& l, const engine::ScenarioSpec* s) {
  if (!l.bus.empty()) return std::nullopt;
  const engine::DelayModel d = f.link_config(l.name, s).delay;
  const std::optional<Duration> ub = d.upper_bound();
  if (!ub) return std::nullopt;
  return *ub - d.lower_bound();
}

/// True when the file has approaches whose sensor samples on a frame's arrival (study ncs's
/// actuation-synchronized ones): the sender of the controller's input is woken by a link.
bool senders_woken_by_links(const engine::StudyFile& f) {
  if (f.study != "ncs") return false;
  for (const engine::ApproachSpec& a : f.approaches) {
    for (ncs::Approach k : ncs::kAllApproaches)
      if (a.kind == ncs::name(k) && ncs::actuation_synchronized(k)) return true;
  }
  return false;
}

/// J of node `node`'s input arrivals under scenario `s` (see study_cpu.hpp); nullopt: unbounded.
std::optional<Duration> input_jitter(const engine::StudyFile& f, const std::string& node, const engine::ScenarioSpec* s) {
  const bool woken = senders_woken_by_links(f);
  Duration j{0};
  for (const engine::LinkSpec& l : f.links) {
    if (l.to != node) continue;
    std::optional<Duration> x = link_spread(f, l, s);
    if (!x) return std::nullopt;
    if (woken) {
      for (const engine::LinkSpec& up : f.links) {
        if (up.to != l.from || up.from == node) continue;
        const std::optional<Duration> y = link_spread(f, up, s);
        if (!y) return std::nullopt;
        *x += *y;
      }
    }
    j = std::max(j, *x);
  }
  return j;
}

/// The field that names task `name` of plan `p` (cpu index `c`).
std::string task_field(const engine::StudyFile& f, const CpuPlan& p, std::size_t c, const std::string& name) {
  for (const auto& [node, task] : p.node_jobs)
    if (p.set.tasks[task].name == name) return at("nodes", node) + ".job";
  const engine::cpu::TaskSet& declared = f.cpus[c];
  for (std::size_t k = 0; k < declared.tasks.size(); ++k)
    if (declared.tasks[k].name == name) return at("cpus", c) + "." + at("tasks", k);
  for (std::size_t k = 0; k < declared.isrs.size(); ++k)
    if (declared.isrs[k].name == name) return at("cpus", c) + "." + at("isrs", k);
  return at("cpus", c);
}

}  // namespace

std::vector<CpuPlan> plan_cpus(const engine::StudyFile& f, std::int64_t h_us) {
  std::vector<CpuPlan> plans;
  const Duration h = engine::from_us(h_us);
  for (std::size_t c = 0; c < f.cpus.size(); ++c) {
    CpuPlan p;
    p.set = f.cpus[c];
    for (std::size_t i = 0; i < f.nodes.size(); ++i) {
      const engine::NodeSpec& n = f.nodes[i];
      if (n.cpu != p.set.name || !n.job) continue;
      const std::string nf = at("nodes", i);
      engine::cpu::TaskSpec t = *n.job;
      if (n.mode == "timer") {  // its own timer: periodic, its first release at the node's phase
        t.external = false;
        t.sporadic = false;
        t.period = n.period;
        t.offset = n.clock_offset;
      } else {
        Duration jmax{0};
        const auto one = [&](const engine::ScenarioSpec* s) {
          const std::optional<Duration> j = input_jitter(f, n.name, s);
          if (!j) {
            refuse(nf + ".cpu", "the arrival of its input has no bound (a link into it, or into its sender, has a delay "
                                "without upper bound or runs on a CAN bus): its job cannot be analysed");
          }
          jmax = std::max(jmax, *j);
        };
        one(nullptr);
        for (const engine::ScenarioSpec& s : f.scenarios) one(&s);
        p.input_jitter = std::max(p.input_jitter, jmax);
        if (h - jmax < engine::from_us(1)) {
          refuse(nf + ".cpu", "its inputs may arrive less than 1 us apart (period h " + std::to_string(h_us) +
                                  " us, arrival spread " + std::to_string(jmax.count() / 1000) + " us)");
        }
        t.period = h - jmax;  // the minimum gap between two input arrivals
        t.max_interarrival = t.period;
      }
      if (t.deadline.count() == 0) t.deadline = n.mode == "timer" ? n.period : h;
      if (t.exec.wcet > t.period) {
        refuse(nf + ".job." + (n.job_exec ? "exec" : "wcet_us"),
               "the worst-case execution time " + std::to_string(us(t.exec.wcet)) + " us exceeds the job's minimum inter-arrival " +
                   std::to_string(us(t.period)) + " us");
      }
      p.node_jobs.emplace_back(i, p.set.tasks.size());
      p.set.tasks.push_back(t);
    }
    if (p.node_jobs.empty()) refuse(at("cpus", c), "no node runs on it (nodes[].cpu): its tasks would run for nothing");
    p.analysis = engine::cpu::analyze(p.set);
    if (!p.analysis.schedulable) {
      refuse(task_field(f, p, c, p.analysis.first_miss), "cpu '" + p.set.name + "' is unschedulable: task '" +
                                                             p.analysis.first_miss + "' may miss its deadline (" + p.analysis.reason + ")");
    }
    plans.push_back(std::move(p));
  }
  return plans;
}

json cpus_json(const engine::StudyFile& f, const std::vector<CpuPlan>& plans) {
  json out = json::array();
  for (const CpuPlan& p : plans) {
    json j = engine::cpu::analysis_json(p.set, p.analysis);
    j["name"] = p.set.name;
    j["context_switch_us"] = us(p.set.context_switch);
    j["input_jitter_us"] = us(p.input_jitter);
    for (std::size_t k = 0; k < p.set.tasks.size(); ++k) {
      json& t = j["tasks"][k];
      t["period_us"] = us(p.set.tasks[k].period);
      t["wcet_us"] = us(p.set.tasks[k].exec.wcet);
      t["bcet_us"] = us(p.set.tasks[k].exec.bcet);
      t["priority"] = p.set.tasks[k].priority;
      t["kind"] = "background";
      for (const auto& [node, task] : p.node_jobs) {
        if (task != k) continue;
        t["kind"] = f.nodes[node].mode == "timer" ? "node job (timer)" : "node job (on input arrival)";
        t["node"] = f.nodes[node].name;
        if (f.nodes[node].role == "sensor") {  // it samples at its start: the analysed lag behind kh
          t["sample_lag_us"] = {t.at("sampling_latency_min_us"), t.at("sampling_latency_max_us")};
        }
      }
    }
    out.push_back(j);
  }
  return out;
}

std::string describe_cpus(const json& cpus) {
  std::ostringstream o;
  for (const json& c : cpus) {
    char buf[256];
    std::snprintf(buf, sizeof buf, "cpu %s: %s, context switch %g us, utilization %.2f %%, %s\n", c.at("name").get<std::string>().c_str(),
                  c.at("scheduler").get<std::string>().c_str(), c.at("context_switch_us").get<double>(),
                  100 * c.at("utilization").get<double>(), c.at("schedulable").get<bool>() ? "schedulable" : "unschedulable");
    o << buf;
    for (const char* list : {"tasks", "isrs"}) {
      for (const json& t : c.at(list)) {
        const std::string wcrt = t.at("wcrt_us").is_null() ? std::string("unbounded") : t.at("wcrt_us").dump();
        o << "  " << (std::string(list) == "isrs" ? "isr" : t.at("kind").get<std::string>()) << " " << t.at("name").get<std::string>();
        if (t.contains("period_us")) o << " (T " << t.at("period_us") << " us, C " << t.at("bcet_us") << "-" << t.at("wcet_us") << " us, priority " << t.at("priority") << ")";
        o << ": WCRT " << wcrt << " us, BCRT " << t.at("bcrt_us") << " us, deadline " << t.at("deadline_us") << " us, "
          << (t.at("schedulable").get<bool>() ? "schedulable" : "misses");
        if (t.contains("sample_lag_us")) {  // the sensor's sample after its release at kh
          o << ", sample lag " << t.at("sample_lag_us")[0] << "-" << t.at("sample_lag_us")[1] << " us";
        }
        o << "\n";
      }
    }
  }
  return o.str();
}

void attach_controller_cpu(const engine::StudyFile& f, NcsStudy& s) {
  if (f.cpus.empty()) return;
  std::optional<std::size_t> sensor_node, controller_node;
  for (std::size_t i = 0; i < f.nodes.size(); ++i) {
    const engine::NodeSpec& n = f.nodes[i];
    if (n.cpu.empty()) continue;
    if (n.role == "sensor") {
      sensor_node = i;
    } else if (n.role == "controller") {
      controller_node = i;
    } else {
      refuse(at("nodes", i) + ".cpu", "the " + n.role + "'s job on a CPU is not modelled in study ncs (it runs on its timer "
                                      "with the loop's own timing)");
    }
    for (std::size_t l = 0; l < f.links.size(); ++l) {
      if (!f.links[l].bus.empty()) {
        refuse(at("nodes", i) + ".cpu", "a " + n.role + " on a CPU with a leg on a CAN bus (" + at("links", l) +
                                            ".bus) is not analysed together: the bus analysis takes the loop's own timing");
      }
    }
  }
  if (sensor_node && controller_node) {
    refuse(at("nodes", *sensor_node) + ".cpu", "the sensor and the controller on CPUs together are not analysed: the controller "
                                               "job's input jitter would take the sensor job's response spread");
  }
  for (std::size_t a = 0; a < f.approaches.size(); ++a) {
    const std::string& k = f.approaches[a].kind;
    if (controller_node && k == "S+") {
      refuse(at("approaches", a) + ".kind", "S+ designs on the mean tau_c, which the schedule of the controller's CPU gives only "
                                            "after the run");
    }
    if (sensor_node && k != "I" && k != "IK" && k != "S" && k != "SK") {
      refuse(at("approaches", a) + ".kind", k + " with the sensor on a CPU: its sampling job runs with the sampling-synchronized "
                                                "approaches S and SK only (I and IK: the delay-free references, not on the CPU)");
    }
  }
  const std::vector<CpuPlan> plans = plan_cpus(f, s.ctx->period_us());
  for (const CpuPlan& p : plans) {
    for (const auto& [node, task] : p.node_jobs) {
      auto c = std::make_shared<ncs::ControllerCpu>();
      c->set = p.set;
      c->task = task;
      // Timer jobs (the one-shot controller's at kh + φ, the sensor's at kh) are released by
      // the node's timer in the loop: analysed as periodic (plan_cpus), run as released then.
      c->set.tasks[task].external = true;
      c->wcrt = p.analysis.tasks[task].wcrt;
      c->bcrt = p.analysis.tasks[task].bcrt;
      c->sample_min = p.analysis.tasks[task].sampling_latency_min;
      c->sample_max = p.analysis.tasks[task].sampling_latency_max;
      const bool sensor = sensor_node && node == *sensor_node;
      for (ncs::Scenario& sc : s.scenarios) (sensor ? sc.sensor_cpu : sc.controller_cpu) = c;
    }
  }
}

}  // namespace oneshot::study
