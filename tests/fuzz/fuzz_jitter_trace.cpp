/// @file fuzz_jitter_trace.cpp
/// @brief libFuzzer harness of the jitter trace parser: parse_jitter_trace(text, source).
///
/// Oracle: an accepted trace has at least one job; every release and execution time is an
/// integer in [0, kMaxJobTimeUs]; each accepted data line holds exactly two integers (the
/// count of accepted jobs equals the count of non-empty, non-comment lines after the header).
#include <cstdint>
#include <sstream>
#include <string>

#include "fuzz_oracle.hpp"
#include "jitter_model.hpp"

using namespace oneshot::sim;
using oneshot::fuzz::require;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  std::vector<JobTiming> trace;
  try {
    trace = parse_jitter_trace(text, "fuzz");
  } catch (const ScenarioError&) {
    return 0;
  }
  require(!trace.empty(), "empty trace accepted");
  for (const JobTiming& t : trace) {
    require(t.release_us >= 0 && t.release_us <= kMaxJobTimeUs, "release out of range");
    require(t.exec_us >= 0 && t.exec_us <= kMaxJobTimeUs, "exec out of range");
  }
  // Independent count of the data lines.
  std::istringstream in(text);
  std::string line;
  std::getline(in, line);
  std::size_t lines = 0;
  while (std::getline(in, line)) {
    const auto first = line.find_first_not_of(" \t\r");
    if (first != std::string::npos && line[first] != '#') ++lines;
  }
  require(lines == trace.size(), "a data line was skipped or split");
  JitterModel m;
  m.kind = JitterModel::Kind::kTrace;
  m.trace = trace;
  require(m.max_busy_us() >= 0 && m.max_busy_us() <= 2 * kMaxJobTimeUs, "busy time");
  return 0;
}
