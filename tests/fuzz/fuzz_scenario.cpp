/// @file fuzz_scenario.cpp
/// @brief libFuzzer harness of the scenario-file parser: parse_scenarios(text, source, …).
///
/// Trace files named in the input are served by a stub (no file system access): "ok.csv"
/// is a two-job trace, anything else is a missing file. Oracle: every accepted scenario
/// has a unique, printable name of 1–100 characters, finite values inside their documented
/// ranges and consistent jitter bounds; validate_scenario against the reference board
/// either accepts it or refuses it with ScenarioError, and an accepted one gives a
/// set-point schedule of codes inside the ADC range.
#include <cmath>
#include <cstdint>
#include <set>
#include <string>

#include "fuzz_oracle.hpp"
#include "oneshot/design/plant_description.hpp"
#include "scenario.hpp"

using namespace oneshot::sim;
using oneshot::fuzz::require;

namespace {

std::vector<JobTiming> stub_trace(const std::string& path) {
  if (path == "ok.csv") return {{1000, 300}, {20'000, 600}};
  throw ScenarioError(path + ": cannot read the jitter trace");
}

bool within(double v, double lo, double hi) { return std::isfinite(v) && v >= lo && v <= hi; }

void check(const Scenario& s, const oneshot::design::PlantDescription& plant) {
  require(!s.name.empty() && s.name.size() <= 100, "name length");
  for (char c : s.name) require(static_cast<unsigned char>(c) >= 0x20 && c != 0x7F, "control character in a name");
  require(within(s.duration_s, 0.05, 1e5), "duration out of range");
  require(within(s.amplitude_volts, 0.0, 1e3), "amplitude out of range");
  require(within(s.change_period_s, 1e-3, 1e5), "change period out of range");
  const JitterModel& j = s.jitter;
  require(j.release_min_us >= 0 && j.release_min_us <= j.release_max_us && j.release_max_us <= kMaxJobTimeUs,
          "release bounds");
  require(j.exec_min_us >= 0 && j.exec_min_us <= j.exec_max_us && j.exec_max_us <= kMaxJobTimeUs, "exec bounds");
  require(j.kind != JitterModel::Kind::kTrace || !j.trace.empty(), "empty trace accepted");
  require(j.max_busy_us() >= 0, "busy time overflow");
  const std::string d = j.describe();
  require(d.find("nan") == std::string::npos && d.find("inf") == std::string::npos, "describe(): " + d);
  try {
    validate_scenario(s, plant);
  } catch (const ScenarioError&) {
    return;
  }
  if (s.duration_s / s.change_period_s > 1e4) return;  // long schedules: not worth the time here
  const SetpointSchedule sch = make_schedule(s, plant, 1);
  require(!sch.code.empty() && sch.at_ns.front() == 0, "schedule starts at 0");
  const std::int32_t top = (1 << plant.board.adc_bits) - 1;
  for (std::int32_t c : sch.code) require(c >= 0 && c <= top, "set-point code outside the ADC range");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const oneshot::design::PlantDescription plant = oneshot::design::reference_plant();
  const std::string text(reinterpret_cast<const char*>(data), size);
  std::vector<Scenario> scenarios;
  try {
    scenarios = parse_scenarios(text, "fuzz", "", stub_trace);
  } catch (const ScenarioError&) {
    return 0;
  }
  require(!scenarios.empty(), "empty scenario list accepted");
  std::set<std::string> names;
  for (const Scenario& s : scenarios) {
    require(names.insert(s.name).second, "duplicate name accepted: " + s.name);
    check(s, plant);
  }
  return 0;
}
