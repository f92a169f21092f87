/// @file fuzz_study_run.cpp
/// @brief libFuzzer harness of `oneshot-sim study run` on what the parser and the ncs mapping
///        accept: the file is parsed with the ncs schema (engine::parse_study), mapped onto the
///        ncs loop (study::map_ncs_study) and RUN, bounded: its first scenarios up to kMaxRuns
///        runs (at least one scenario), one seed, every scenario's simulated time capped by study::cap_duration (the
///        runner's `--max-duration`) at min(0.3 s, 20 periods h), at least h. The node timers
///        run once per period, so the cap bounds the events and frames of a run; an oracle
///        checks it (frames a link carries per run ≤ periods + 2).
///
/// Oracles: no crash; bad input refused by the parser (engine::InputError), what the loop
/// cannot run refused by the mapping or the cap with engine::InputError naming the field
/// ("field '…'"); a run gives finite metrics (cost, counters; with
/// --analytic, chosen by the input's length, the exact expected cost too), its link counters
/// add up (delivered + lost = sent, late + refused ≤ delivered) and the summary of
/// `study run` (study::run_outputs, CSV and markdown files, no plots) holds only finite
/// numbers (null for unbounded delays). Inputs are parsed as files in the harness's folder
/// (study_fuzz_support.hpp: study ncs's plant file "networked_board.json" and a delay trace
/// "delays.csv" beside them; on /dev/shm where there is one, the summary's files being synced
/// writes that would cost more than the runs on a disk).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "fuzz_oracle.hpp"
#include "study_fuzz_support.hpp"
#include "oneshot/engine/study_file.hpp"
#include "study_ncs_runner.hpp"
#include "study_ncs_sweep.hpp"

namespace e = oneshot::engine;
namespace st = oneshot::study;
using oneshot::fuzz::require;
using oneshot::fuzz::require_finite_json;
using oneshot::fuzz::require_named;

namespace {

/// Runs (approaches × scenarios, one seed) per input at most: the file's first scenarios, at
/// least one (9 runs, and as many analytic ones, take ~40 ms under ASan).
constexpr std::size_t kMaxRuns = 9;
/// Simulated seconds per run at most (and at most kMaxPeriods periods h, at least one).
constexpr double kMaxDurationS = 0.3;
/// Periods h per run at most.
constexpr double kMaxPeriods = 20;

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string& dir = oneshot::fuzz::study_folder(ONESHOT_NCS_PLANT_FILE);
  const std::string text(reinterpret_cast<const char*>(data), size);
  e::StudyFile file;
  try {
    file = e::parse_study(text, dir + "/fuzz.json", &st::ncs_schema(), dir);
  } catch (const e::InputError&) {
    return 0;  // refused by the parser with a message (fuzz_study checks those): fine
  }
  st::NcsStudy s;
  try {
    s = st::map_ncs_study(file);
    const std::size_t scenarios = std::max<std::size_t>(1, kMaxRuns / s.approaches.size());
    if (s.scenarios.size() > scenarios) s.scenarios.resize(scenarios);
    for (st::NcsStudy& l : s.loops)  // several loops: each loop's scenarios too
      if (l.scenarios.size() > scenarios) l.scenarios.resize(scenarios);
    const double h_s = static_cast<double>(s.ctx->period_us()) * 1e-6;
    st::cap_duration(s, std::fmax(h_s, std::fmin(kMaxDurationS, kMaxPeriods * h_s)), "--max-duration");
  } catch (const e::InputError& x) {
    require_named(x, "study run");
    return 0;
  }
  bool analytic = size % 2 == 1;
  // The one-shot loops have no analytic cost (refused naming '--analytic': StudyOneShot.*).
  for (oneshot::ncs::Approach a : s.approaches) analytic = analytic && !oneshot::ncs::one_shot(a);
  analytic = analytic && s.loops.empty();  // several loops: refused naming '--analytic' (StudyLoops.*)
  const e::SweepResults r = st::run_ncs_sweep(s, 1, 1, e::Shard{}, analytic);
  require(r.complete(), "study run: a run missing");
  for (double v : r.values) require(std::isfinite(v), "study run: a non-finite metric");
  std::vector<const st::NcsStudy*> loops{&s};  // several loops: each, its metrics "<loop>/..."
  if (!s.loops.empty()) {
    loops.clear();
    for (const st::NcsStudy& l : s.loops) loops.push_back(&l);
  }
  for (std::size_t a = 0; a < r.spec.approaches.size(); ++a) {
    for (std::size_t k = 0; k < r.spec.scenarios.size(); ++k) {
      for (const st::NcsStudy* loop : loops) {
        const std::string prefix = loop->loop.empty() ? "" : loop->loop + "/";
        const double periods = loop->scenarios[k].duration_s * 1e6 / static_cast<double>(loop->ctx->period_us());
        for (const std::string& l : loop->links) {
          const auto at = [&](const char* c) { return r.at(a, k, 0, r.metric(prefix + l + "." + c)); };
          const std::string where = r.spec.approaches[a] + " on " + r.spec.scenarios[k] + ", link " + l;
          require(at("sent") <= periods + 2, where + ": more frames than periods (" + std::to_string(at("sent")) + ")");
          require(at("delivered") + at("lost") == at("sent"), where + ": delivered + lost != sent");
          require(at("late") + at("refused") <= at("delivered"), where + ": more late or refused frames than delivered");
        }
      }
    }
  }
  require_finite_json(st::run_outputs(r, dir + "/out", false), "summary", "study run");
  return 0;
}
