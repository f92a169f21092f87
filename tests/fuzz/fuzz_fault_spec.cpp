/// @file fuzz_fault_spec.cpp
/// @brief libFuzzer harness of the fault spec and the link fault models: the input up to
///        the first NUL is a spec (engine::parse_fault_spec), the rest a stream of frames
///        (1 length byte, then that many bytes) sent 1 ms apart through LinkFaults.
///
/// Oracle: a refused spec is an InputError; an accepted one has only known kinds, values
/// in their documented ranges, and its clauses' canonical text parses back to the same
/// text; LinkFaults never changes a frame's size, adds only frames of sizes already sent,
/// and counts exactly one effect or skip per hit it reports.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <set>
#include <string>
#include <vector>

#include "fuzz_oracle.hpp"
#include "oneshot/engine/frame_faults.hpp"
#include "oneshot/engine/json_fields.hpp"

using namespace oneshot::engine;
using oneshot::fuzz::require;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::size_t nul = 0;
  while (nul < size && data[nul] != 0) ++nul;
  const std::string text(reinterpret_cast<const char*>(data), nul);
  FaultSpec spec;
  try {
    spec = parse_fault_spec(text);
  } catch (const InputError&) {
    return 0;
  }
  for (const FaultClause& c : spec.clauses) {
    require(c.rate >= 0 && c.rate <= 1, "rate out of range");
    require(std::isfinite(c.at_s) && c.at_s >= 0 && c.at_s <= 1e6, "at_s out of range");
    require(c.bits >= 1 && c.bits <= 64, "bits out of range");
    require(c.age.count() >= 1'000'000 && c.age.count() <= 60'000'000'000, "age out of range");
    require(c.jump >= 1, "jump 0");
    require(is_frame_fault(c.kind) ? (c.once || c.rate > 0) : (!c.node.empty() && c.once), "clause that never fires");
    const std::string canonical = to_text(c);
    const FaultSpec back = parse_fault_spec(canonical);
    require(back.clauses.size() == 1 && to_text(back.clauses[0]) == canonical, "canonical text: " + canonical);
  }
  LinkFaults faults(spec, "l", FrameLayout{0, 4, 8, 8}, 1);
  std::set<std::size_t> sizes;
  std::uint64_t before = 0;
  std::size_t i = nul + 1;
  for (std::int64_t t = 0; i < size; t += 1'000'000) {
    const std::size_t n = data[i++];
    std::vector<std::uint8_t> frame(data + i, data + std::min(size, i + n));
    i += n;
    sizes.insert(frame.size());
    const std::size_t sent = frame.size();
    std::vector<std::vector<std::uint8_t>> extra;
    faults.apply(SimTime{t}, frame, extra);
    require(frame.size() == sent, "a fault changed a frame's size");
    for (const auto& e : extra) require(sizes.count(e.size()) == 1, "an added frame of a size never sent");
    const FaultCounters& c = faults.counters();
    const std::uint64_t now = c.injected() + c.skipped;
    require(now - before <= spec.clauses.size(), "more effects than clauses on one frame");
    require(extra.size() <= spec.clauses.size(), "more added frames than clauses");
    before = now;
  }
  return 0;
}
