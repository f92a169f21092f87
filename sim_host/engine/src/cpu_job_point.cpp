/// @file cpu_job_point.cpp
/// @brief Sample and actuation points in a job: offsets, parsing, ordering (cpu_job_point.hpp).
#include "oneshot/engine/cpu_job_point.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include "oneshot/engine/json_fields.hpp"

namespace oneshot::engine::cpu {

namespace {

[[noreturn]] void fail(const std::string& field, const std::string& why) { throw InputError("field '" + field + "': " + why); }

constexpr const char* kForms = "\"start\", \"end\", a fraction in [0, 1], {\"fraction\"}, {\"instructions\"} or {\"us\"}";

/// t = ⌈n · 1000 / MIPS⌉ ns (as instruction_time in cpu_task_set.hpp).
Duration instr_time(std::uint64_t n, double mips) {
  return Duration{static_cast<std::int64_t>(std::ceil(static_cast<double>(n) * 1000.0 / mips - 1e-9))};
}

JobPoint fraction_point(double f, const std::string& field) {
  if (!std::isfinite(f) || f < 0 || f > 1) fail(field, "fraction must be in [0, 1]");
  JobPoint p;
  p.kind = JobPoint::Kind::kFraction;
  p.fraction = f;
  return p;
}

}  // namespace

Duration JobPoint::offset(Duration exec) const {
  switch (kind) {
    case Kind::kStart: return Duration{0};
    case Kind::kEnd: return exec;
    case Kind::kFraction:
      // ⌊f·e⌋ ns
      return std::min(exec, Duration{static_cast<std::int64_t>(std::floor(fraction * static_cast<double>(exec.count())))});
    case Kind::kInstructions: return std::min(exec, instr_time(instructions, clock_mips));
    case Kind::kTime: return std::min(exec, time);
  }
  return Duration{0};
}

JobPoint parse_job_point(const nlohmann::json& j, const std::string& field, double default_mips) {
  if (j.is_string()) {
    const std::string s = j.get<std::string>();
    if (s == "start") return job_start();
    if (s == "end") return job_end();
    fail(field, "unknown point '" + s + "' (" + kForms + ")");
  }
  if (j.is_number()) return fraction_point(j.get<double>(), field);
  if (!j.is_object() || j.size() == 0) fail(field, std::string("must be ") + kForms);
  require_keys(j, field, {"fraction", "instructions", "clock_mips", "us"});
  const int forms = static_cast<int>(j.contains("fraction")) + static_cast<int>(j.contains("instructions")) +
                    static_cast<int>(j.contains("us"));
  if (forms != 1) fail(field, "give exactly one of fraction, instructions, us");
  if (j.contains("fraction")) return fraction_point(number_in(j, field, "fraction", 0, 1), field + ".fraction");
  JobPoint p;
  if (j.contains("us")) {
    if (j.contains("clock_mips")) fail(field + ".clock_mips", "only with instructions");
    p.kind = JobPoint::Kind::kTime;
    p.time = from_us(integer_in(j, field, "us", 0, 3'600'000'000));
    return p;
  }
  p.kind = JobPoint::Kind::kInstructions;
  p.instructions = static_cast<std::uint64_t>(integer_in(j, field, "instructions", 0, std::int64_t{1} << 50));
  p.clock_mips = number_in(j, field, "clock_mips", 1e-3, 1e6, true, default_mips);
  if (p.clock_mips <= 0) fail(field + ".clock_mips", "missing (the task's execution model states no clock)");
  return p;
}

JobPoint parse_job_point_text(const std::string& text, const std::string& field, double mips) {
  if (text == "start") return job_start();
  if (text == "end") return job_end();
  auto number = [&](const std::string& s) {
    std::size_t used = 0;
    double v = 0;
    try {
      v = std::stod(s, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || used != s.size() || !std::isfinite(v) || v < 0) {
      fail(field, "'" + text + "' is not start, end, a fraction, <n>us or <n>instr");
    }
    return v;
  };
  JobPoint p;
  const auto ends = [&](const std::string& suffix) {
    return text.size() > suffix.size() && text.compare(text.size() - suffix.size(), suffix.size(), suffix) == 0;
  };
  if (ends("instr")) {
    const double n = number(text.substr(0, text.size() - 5));
    if (n != std::floor(n) || n > 1e15) fail(field, "instruction count must be a whole number");
    p.kind = JobPoint::Kind::kInstructions;
    p.instructions = static_cast<std::uint64_t>(n);
    p.clock_mips = mips;
    return p;
  }
  if (ends("us")) {
    const double t = number(text.substr(0, text.size() - 2));
    if (t > 3.6e9) fail(field, "time beyond one hour");
    p.kind = JobPoint::Kind::kTime;
    p.time = Duration{static_cast<std::int64_t>(std::llround(t * 1e3))};
    return p;
  }
  return fraction_point(number(text), field);
}

nlohmann::json job_point_json(const JobPoint& p) {
  switch (p.kind) {
    case JobPoint::Kind::kStart: return "start";
    case JobPoint::Kind::kEnd: return "end";
    case JobPoint::Kind::kFraction: return p.fraction;
    case JobPoint::Kind::kInstructions: return {{"instructions", p.instructions}, {"clock_mips", p.clock_mips}};
    case JobPoint::Kind::kTime: return {{"us", static_cast<double>(p.time.count()) * 1e-3}};
  }
  return "start";
}

namespace {

/// The execution times where offset differences may be smallest: bcet, wcet, breakpoints.
std::vector<Duration> check_points(const JobPoint& sample, const JobPoint& actuate, Duration bcet, Duration wcet) {
  std::vector<Duration> at = {bcet, wcet};
  for (const JobPoint* p : {&sample, &actuate}) {
    Duration b{-1};
    if (p->kind == JobPoint::Kind::kTime) b = p->time;
    if (p->kind == JobPoint::Kind::kInstructions) b = instr_time(p->instructions, p->clock_mips);
    if (b >= bcet && b <= wcet) at.push_back(b);
  }
  return at;
}

}  // namespace

Duration min_work_between(const JobPoint& sample, const JobPoint& actuate, Duration bcet, Duration wcet) {
  Duration m = actuate.offset(bcet) - sample.offset(bcet);
  for (const Duration e : check_points(sample, actuate, bcet, wcet)) m = std::min(m, actuate.offset(e) - sample.offset(e));
  return m;
}

void check_point_order(const JobPoint& sample, const JobPoint& actuate, Duration bcet, Duration wcet, const std::string& field) {
  for (const Duration e : check_points(sample, actuate, bcet, wcet)) {
    if (actuate.offset(e) < sample.offset(e)) {
      fail(field, "comes before sample_at for a job of " + std::to_string(static_cast<double>(e.count()) * 1e-3) + " us");
    }
  }
}

}  // namespace oneshot::engine::cpu
