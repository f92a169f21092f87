/// @file cpu_task_set.cpp
/// @brief Task sets: execution-time draws and the strict task-file parser.
#include "oneshot/engine/cpu_task_set.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <set>
#include <sstream>

#include "oneshot/engine/json_fields.hpp"
#include "oneshot/util/enum_names.hpp"
#include "oneshot/util/file_io.hpp"

namespace oneshot::engine::cpu {

namespace {

constexpr std::int64_t kMaxUs = 3'600'000'000;  // one hour: any period, deadline or offset

Duration us(std::int64_t v) { return from_us(v); }

std::string at(const std::string& where, const char* key) { return where.empty() ? key : where + "." + key; }

[[noreturn]] void fail(const std::string& field, const std::string& why) {
  throw InputError("field '" + field + "': " + why);
}

/// Reads a one-column CSV trace "exec_us" (whole µs, > 0).
std::vector<Duration> read_exec_trace(const std::string& path, const std::string& field) {
  std::string text;
  try {
    text = util::read_text_file(path, "execution-time trace");
  } catch (const util::FileError& e) {
    fail(field, e.what());
  }
  std::istringstream in(text);
  std::string line;
  std::vector<Duration> v;
  std::size_t n = 0;
  bool header = false;
  while (std::getline(in, line)) {
    ++n;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty() || line[0] == '#') continue;
    if (!header) {
      if (line != "exec_us") fail(field, path + " line " + std::to_string(n) + ": expected the header 'exec_us'");
      header = true;
      continue;
    }
    std::size_t used = 0;
    long long x = 0;
    try {
      x = std::stoll(line, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used != line.size() || x <= 0 || x > kMaxUs) {
      fail(field, path + " line " + std::to_string(n) + ": expected an integer in [1, " + std::to_string(kMaxUs) + "]");
    }
    v.push_back(us(x));
  }
  if (v.empty()) fail(field, path + ": no execution times");
  return v;
}

/// Instruction counts from an `oneshot-sim exectime --target … --json FILE` output.
void read_exectime_file(ExecModel& m, const std::string& path, const std::string& variant, const std::string& field) {
  std::string text;
  try {
    text = util::read_text_file(path, "exectime file");
  } catch (const util::FileError& e) {
    fail(field + ".exectime_file", e.what());
  }
  const nlohmann::json j = parse_json_strict(text, path);
  if (!j.is_object() || !j.contains("variants") || !j["variants"].is_object() || !j["variants"].contains(variant)) {
    fail(field + ".variant", "'" + variant + "' not in " + path + " (variants of `oneshot-sim exectime --json`)");
  }
  const nlohmann::json& v = j["variants"][variant];
  const std::string w = field + ".variant";
  // Counts are written as JSON numbers (possibly 3822.0): whole, positive.
  for (const char* key : {"instructions_per_job_min", "instructions_per_job_max"}) {
    const double x = number_in(v, w, key, 1, 1e15);
    if (x != std::floor(x)) fail(w + "." + key, "must be a whole number of instructions");
    (std::string(key).back() == 'n' ? m.instructions_min : m.instructions_max) = static_cast<std::uint64_t>(x);
  }
  m.source = path + " variant " + variant + (j.contains("target") && j["target"].is_string()
                                                 ? " (target " + j["target"].get<std::string>() + ")"
                                                 : std::string());
}

}  // namespace

ExecModel parse_exec_model(const nlohmann::json& j, const std::string& f, const std::string& base_dir) {
  ExecModel m;
  const std::string model = string_of(j, f, "model");
  if (model == "constant") {
    require_keys(j, f, {"model", "time_us"});
    m.kind = ExecModel::Kind::kConstant;
    m.bcet = m.wcet = us(integer_in(j, f, "time_us", 1, kMaxUs));
  } else if (model == "uniform") {
    require_keys(j, f, {"model", "bcet_us", "wcet_us"});
    m.kind = ExecModel::Kind::kUniform;
    m.wcet = us(integer_in(j, f, "wcet_us", 1, kMaxUs));
    m.bcet = us(integer_in(j, f, "bcet_us", 1, kMaxUs));
    if (m.bcet > m.wcet) fail(at(f, "bcet_us"), "exceeds wcet_us");
  } else if (model == "histogram") {
    require_keys(j, f, {"model", "values_us", "weights"});
    m.kind = ExecModel::Kind::kEmpirical;
    const nlohmann::json& vs = member(j, f, "values_us");
    const nlohmann::json& ws = member(j, f, "weights");
    if (!vs.is_array() || vs.empty() || vs.size() > 100000) fail(at(f, "values_us"), "must be a non-empty array");
    if (!ws.is_array() || ws.size() != vs.size()) fail(at(f, "weights"), "must be an array as long as values_us");
    double total = 0;
    for (std::size_t i = 0; i < vs.size(); ++i) {
      const nlohmann::json wrap = {{"v", vs[i]}, {"w", ws[i]}};
      m.values.push_back(us(integer_in(wrap, at(f, "values_us") + "[" + std::to_string(i) + "]", "v", 1, kMaxUs)));
      m.weights.push_back(number_in(wrap, at(f, "weights") + "[" + std::to_string(i) + "]", "w", 0, 1e12));
      total += m.weights.back();
    }
    if (!(total > 0)) fail(at(f, "weights"), "must not all be zero");
  } else if (model == "trace") {
    require_keys(j, f, {"model", "file"});
    m.kind = ExecModel::Kind::kEmpirical;
    std::filesystem::path p(string_of(j, f, "file"));
    if (p.is_relative()) p = std::filesystem::path(base_dir) / p;
    m.values = read_exec_trace(p.string(), at(f, "file"));
    m.source = p.string();
  } else if (model == "instructions") {
    require_keys(j, f, {"model", "clock_mips", "instructions", "instructions_min", "instructions_max", "exectime_file",
                        "variant"});
    m.kind = ExecModel::Kind::kInstructions;
    m.whole_us = false;
    m.clock_mips = number_in(j, f, "clock_mips", 0.001, 1e6);
    if (j.contains("exectime_file")) {
      if (j.contains("instructions") || j.contains("instructions_min")) {
        fail(at(f, "exectime_file"), "give either an exectime file or instruction counts");
      }
      std::filesystem::path p(string_of(j, f, "exectime_file"));
      if (p.is_relative()) p = std::filesystem::path(base_dir) / p;
      read_exectime_file(m, p.string(), string_of(j, f, "variant"), f);
    } else if (j.contains("instructions")) {
      m.instructions_min = m.instructions_max = static_cast<std::uint64_t>(integer_in(j, f, "instructions", 1, INT64_MAX / 2));
    } else {
      m.instructions_min = static_cast<std::uint64_t>(integer_in(j, f, "instructions_min", 1, INT64_MAX / 2));
      m.instructions_max = static_cast<std::uint64_t>(integer_in(j, f, "instructions_max", 1, INT64_MAX / 2));
    }
    if (m.instructions_min > m.instructions_max) fail(at(f, "instructions_min"), "exceeds instructions_max");
  } else {
    fail(at(f, "model"), "unknown execution-time model '" + model + "' (constant, uniform, histogram, trace, instructions)");
  }
  if (m.kind == ExecModel::Kind::kEmpirical) {
    m.bcet = *std::min_element(m.values.begin(), m.values.end());
    m.wcet = *std::max_element(m.values.begin(), m.values.end());
  } else if (m.kind == ExecModel::Kind::kInstructions) {
    m.bcet = instruction_time(m.instructions_min, m.clock_mips);
    m.wcet = instruction_time(m.instructions_max, m.clock_mips);
  }
  return m;
}

namespace {

constexpr util::EnumName<SchedulerKind> kSchedulerNames[] = {{SchedulerKind::kFixedPriority, "fixed_priority"},
                                                             {SchedulerKind::kFixedPriorityNonPreemptive, "fixed_priority_nonpreemptive"},
                                                             {SchedulerKind::kEdf, "edf"}};
constexpr util::EnumName<OverrunPolicy> kOverrunNames[] = {
    {OverrunPolicy::kContinue, "continue"}, {OverrunPolicy::kSkip, "skip"}, {OverrunPolicy::kAbort, "abort"}};

OverrunPolicy parse_overrun(const std::string& s, const std::string& field) {
  if (const auto p = util::enum_value(kOverrunNames, s)) return *p;
  fail(field, "unknown overrun policy '" + s + "' (" + util::enum_name_list(kOverrunNames) + ")");
}

TaskSpec parse_task(const nlohmann::json& j, const std::string& f, bool isr, const std::string& base_dir) {
  if (isr) {
    require_keys(j, f, {"name", "kind", "period_us", "max_interarrival_us", "offset_us", "cost_us", "bcet_us",
                        "priority", "jitter_us"});
  } else {
    require_keys(j, f, {"name", "kind", "period_us", "max_interarrival_us", "wcet_us", "bcet_us", "exec", "priority",
                        "offset_us", "deadline_us", "jitter_us", "nonpreemptive_us", "overrun", "sample_at", "actuate_at"});
  }
  TaskSpec t;
  t.name = string_of(j, f, "name");
  if (t.name.size() > 100) fail(at(f, "name"), "longer than 100 characters");
  const std::string kind = string_of(j, f, "kind", true, "periodic");
  if (kind != "periodic" && kind != "sporadic") fail(at(f, "kind"), "must be 'periodic' or 'sporadic'");
  t.sporadic = kind == "sporadic";
  t.period = us(integer_in(j, f, "period_us", 1, kMaxUs));
  t.max_interarrival = us(integer_in(j, f, "max_interarrival_us", 1, kMaxUs, true, t.period.count() / 1000));
  if (t.max_interarrival < t.period) fail(at(f, "max_interarrival_us"), "below period_us");
  if (!t.sporadic && j.contains("max_interarrival_us")) fail(at(f, "max_interarrival_us"), "only for sporadic tasks");
  t.offset = us(integer_in(j, f, "offset_us", 0, kMaxUs, true, 0));
  t.priority = static_cast<int>(integer_in(j, f, "priority", 1, 1'000'000, isr, 1));
  t.release_jitter = us(integer_in(j, f, "jitter_us", 0, kMaxUs, true, 0));
  const char* wkey = isr ? "cost_us" : "wcet_us";
  if (!isr && j.contains("exec")) {
    if (j.contains("wcet_us") || j.contains("bcet_us")) fail(at(f, "exec"), "give either exec or wcet_us/bcet_us");
    t.exec = parse_exec_model(member(j, f, "exec"), at(f, "exec"), base_dir);
  } else {
    t.exec.wcet = us(integer_in(j, f, wkey, 1, kMaxUs));
    t.exec.bcet = us(integer_in(j, f, "bcet_us", 1, kMaxUs, true, t.exec.wcet.count() / 1000));
    if (t.exec.bcet > t.exec.wcet) fail(at(f, "bcet_us"), std::string("exceeds ") + wkey);
    t.exec.kind = t.exec.bcet == t.exec.wcet ? ExecModel::Kind::kConstant : ExecModel::Kind::kUniform;
  }
  if (t.exec.wcet > t.period) fail(at(f, wkey), "exceeds period_us");
  t.deadline = isr ? t.period : us(integer_in(j, f, "deadline_us", 1, kMaxUs, true, t.period.count() / 1000));
  if (!isr) {
    t.nonpreemptive = us(integer_in(j, f, "nonpreemptive_us", 0, kMaxUs, true, 0));
    if (t.nonpreemptive > t.exec.bcet) fail(at(f, "nonpreemptive_us"), "exceeds the best-case execution time");
    t.overrun = parse_overrun(string_of(j, f, "overrun", true, "continue"), at(f, "overrun"));
    const double mips = t.exec.kind == ExecModel::Kind::kInstructions ? t.exec.clock_mips : 0.0;
    if (j.contains("sample_at")) t.sample_at = parse_job_point(j["sample_at"], at(f, "sample_at"), mips);
    if (j.contains("actuate_at")) t.actuate_at = parse_job_point(j["actuate_at"], at(f, "actuate_at"), mips);
    check_point_order(t.sample_at, t.actuate_at, t.exec.bcet, t.exec.wcet, at(f, "actuate_at"));
  }
  return t;
}

}  // namespace

Duration instruction_time(std::uint64_t instructions, double mips) {
  return Duration{static_cast<std::int64_t>(std::ceil(static_cast<double>(instructions) * 1000.0 / mips - 1e-9))};
}

Duration ExecModel::draw(RandomStream& rng, std::uint64_t k) const {
  switch (kind) {
    case Kind::kConstant:
      return wcet;
    case Kind::kUniform:
      if (whole_us) return from_us(rng.uniform_int(bcet.count() / 1000, wcet.count() / 1000));
      return Duration{rng.uniform_int(bcet.count(), wcet.count())};
    case Kind::kInstructions:
      return instruction_time(static_cast<std::uint64_t>(rng.uniform_int(static_cast<std::int64_t>(instructions_min),
                                                                          static_cast<std::int64_t>(instructions_max))),
                              clock_mips);
    case Kind::kEmpirical:
      if (weights.empty()) return values[k % values.size()];
      {
        double total = 0;
        for (double w : weights) total += w;
        double u = rng.uniform01() * total;
        for (std::size_t i = 0; i < values.size(); ++i) {
          if (u < weights[i]) return values[i];
          u -= weights[i];
        }
        return values.back();
      }
  }
  return wcet;
}

double TaskSet::utilization() const {
  double u = 0;
  for (const auto* list : {&tasks, &isrs}) {
    for (const TaskSpec& t : *list) u += static_cast<double>(t.exec.wcet.count()) / static_cast<double>(t.period.count());
  }
  return u;
}

const char* to_string(SchedulerKind s) { return util::enum_name(kSchedulerNames, s); }

const char* to_string(OverrunPolicy p) { return util::enum_name(kOverrunNames, p); }

TaskSet parse_task_set_json(const nlohmann::json& root, const std::string& prefix, const std::string& base_dir,
                            bool allow_no_tasks) {
  require_keys(root, prefix, {"name", "scheduler", "context_switch_us", "tasks", "isrs"});
  TaskSet s;
  s.name = string_of(root, prefix, "name", true, "cpu");
  if (s.name.size() > 100) fail(at(prefix, "name"), "longer than 100 characters");
  const std::string sched = string_of(root, prefix, "scheduler");
  const auto kind = util::enum_value(kSchedulerNames, sched);
  if (!kind) fail(at(prefix, "scheduler"), "unknown scheduler '" + sched + "' (" + util::enum_name_list(kSchedulerNames) + ")");
  s.scheduler = *kind;
  s.context_switch = us(integer_in(root, prefix, "context_switch_us", 0, 1'000'000, true, 0));
  std::set<std::string> names;
  for (const char* list : {"tasks", "isrs"}) {
    const bool isr = std::string(list) == "isrs";
    const std::string lf = at(prefix, list);
    if (!root.contains(list)) {
      if (!isr && !allow_no_tasks) fail(lf, "missing");
      continue;
    }
    const nlohmann::json& a = root[list];
    if (!a.is_array() || a.size() > 1000) fail(lf, "must be an array of at most 1000 entries");
    if (!isr && a.empty() && !allow_no_tasks) fail(lf, "must hold at least one task");
    for (std::size_t i = 0; i < a.size(); ++i) {
      const std::string f = lf + "[" + std::to_string(i) + "]";
      TaskSpec t = parse_task(a[i], f, isr, base_dir);
      if (!names.insert(t.name).second) fail(f + ".name", "duplicate name '" + t.name + "'");
      (isr ? s.isrs : s.tasks).push_back(std::move(t));
    }
  }
  return s;
}

TaskSpec parse_node_job(const nlohmann::json& j, const std::string& field, const std::string& name, const std::string& base_dir) {
  require_keys(j, field, {"wcet_us", "bcet_us", "exec", "priority", "deadline_us", "nonpreemptive_us", "overrun"});
  nlohmann::json task = j;  // the task parser's keys, with the name and a period the runner replaces
  task["name"] = name;
  task["period_us"] = kMaxUs;
  TaskSpec t = parse_task(task, field, false, base_dir);
  t.external = true;
  t.sporadic = true;
  t.period = Duration{0};
  t.max_interarrival = Duration{0};
  if (!j.contains("deadline_us")) t.deadline = Duration{0};
  return t;
}

TaskSet parse_task_set(const std::string& text, const std::string& source, const std::string& base_dir) {
  try {
    return parse_task_set_json(parse_json_strict(text, source), "", base_dir, false);
  } catch (const InputError& e) {
    std::string m = e.what();
    const std::string lead = "field '.";
    if (m.rfind(lead, 0) == 0) m = "field '" + m.substr(lead.size());
    throw InputError(source + ": " + m);
  }
}

TaskSet load_task_set(const std::string& path) {
  const std::string text = util::read_text_file_as<InputError>(path, "task file");
  return parse_task_set(text, path, std::filesystem::path(path).parent_path().string());
}

nlohmann::json task_set_json(const TaskSet& set) {
  auto one = [](const TaskSpec& t, bool isr) {
    nlohmann::json j = {{"name", t.name},
                        {"kind", t.sporadic ? "sporadic" : "periodic"},
                        {"period_us", t.period.count() / 1000},
                        {"offset_us", t.offset.count() / 1000},
                        {"priority", t.priority},
                        {isr ? "cost_us" : "wcet_us", (t.exec.wcet.count() + 999) / 1000},
                        {"bcet_us", std::max<std::int64_t>(1, t.exec.bcet.count() / 1000)}};
    if (t.sporadic) j["max_interarrival_us"] = t.max_interarrival.count() / 1000;
    if (!isr) {
      j["deadline_us"] = t.deadline.count() / 1000;
      j["overrun"] = to_string(t.overrun);
      if (t.sample_at.kind != JobPoint::Kind::kStart) j["sample_at"] = job_point_json(t.sample_at);
      if (t.actuate_at.kind != JobPoint::Kind::kEnd) j["actuate_at"] = job_point_json(t.actuate_at);
    }
    if (t.release_jitter.count() > 0) j["jitter_us"] = t.release_jitter.count() / 1000;
    if (t.nonpreemptive.count() > 0) j["nonpreemptive_us"] = t.nonpreemptive.count() / 1000;
    return j;
  };
  nlohmann::json j = {{"name", set.name},
                      {"scheduler", to_string(set.scheduler)},
                      {"context_switch_us", set.context_switch.count() / 1000},
                      {"tasks", nlohmann::json::array()},
                      {"isrs", nlohmann::json::array()}};
  for (const TaskSpec& t : set.tasks) j["tasks"].push_back(one(t, false));
  for (const TaskSpec& t : set.isrs) j["isrs"].push_back(one(t, true));
  return j;
}

}  // namespace oneshot::engine::cpu
