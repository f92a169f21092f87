/// @file fuzz_study_run.cpp
/// @brief libFuzzer harness of `oneshot-sim study run` on what the parser and the mappings
///        accept. The input is parsed without a schema (engine::parse_study) for its "study",
///        as `study run` does; a "dropping", "sod", "petc" or "oneshot" file is parsed again with
///        its study's schema, mapped (map_<study>_study) and RUN, bounded (below); any other
///        with the ncs schema, mapped onto the ncs loop (study::map_ncs_study) and RUN, bounded:
///        its first scenarios up to kMaxRuns runs (at least one scenario), one seed, every
///        scenario's simulated time capped by study::cap_duration (the runner's
///        `--max-duration`) at min(0.3 s, 20 periods h), at least h. The node timers run once
///        per period, so the cap bounds the events and frames of a run; an oracle checks it
///        (frames a link carries per run ≤ periods + 2).
///
/// The other studies refuse --max-duration; their runs are bounded by editing the mapped
/// study: at most kMaxRuns approaches (the file's first), their first scenarios up to kMaxRuns
/// runs (at least one), one seed, and each scenario's length cut: dropping and sod at
/// kMaxSteps steps (the mapped runs' `steps`; sod's δt design runs at the same steps; a sod
/// input needing more than kMaxSodDesigns δt designs after the cut is skipped), oneshot
/// at min(0.3 s, 20 h), at least h (the scenarios' duration_s; a CPU's schedule spans the
/// same). A petc file's mapping designs over the whole horizon K (its TTS response), so petc
/// inputs longer than kMaxPetcSeconds (50 periods of the petc plant's 20 us) or of a mapped
/// K above kMaxSteps are skipped, not cut.
///
/// Oracles: no crash; bad input refused by the parser (engine::InputError), what a loop
/// cannot run refused by the mapping or the cap with engine::InputError naming the field
/// ("field '…'"; so must a sweep's refusal: sod's failed δt design); a run gives finite metrics (cost, counters; with --analytic, chosen by the
/// input's length, the exact expected cost too), except the non-finite ones a study
/// documents (dropping: a diverging loop's cost, err, trace_p; gamma but the buffered filter's), its link counters add up (ncs: delivered + lost =
/// sent, late + refused ≤ delivered; dropping and sod: lost ≤ sent ≤ steps + 1) and the
/// summary of `study run` (study::run_outputs and the other studies' <study>_run_outputs, CSV
/// and markdown files, no plots) holds only finite numbers (null for unbounded delays and
/// non-finite means) and, per approach and link, delivered + lost = sent. Inputs are parsed as
/// files in the harness's folder (study_fuzz_support.hpp: study ncs's plant file
/// "networked_board.json" and a delay trace "delays.csv" beside them, and here the other
/// studies' plant files "sinopoli_dropping.json", "send_on_delta_oscillator.json",
/// "hdd_numre.json", "reference_board.json"; on /dev/shm where there is one, the summary's
/// files being synced writes that would cost more than the runs on a disk).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <type_traits>
#include <vector>

#include "fuzz_oracle.hpp"
#include "study_fuzz_support.hpp"
#include "oneshot/engine/study_file.hpp"
#include "study_dropping_runner.hpp"
#include "study_dropping_study.hpp"
#include "study_ncs_runner.hpp"
#include "study_ncs_sweep.hpp"
#include "study_oneshot_study.hpp"
#include "study_petc_study.hpp"
#include "study_sod_runner.hpp"
#include "study_sod_study.hpp"

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
/// Steps per run at most of the dropping and sod loops (one period T each).
constexpr std::size_t kMaxSteps = 50;
/// Longest scenario of a petc file that is mapped and run (50 periods of the petc plant's 20 us:
/// 7 runs of a NUMRE loop over 100 periods took ~80 ms per input under ASan).
constexpr double kMaxPetcSeconds = 0.001;
/// msod's δt designs per sod input at most (inputs needing more, after the cut, are skipped).
constexpr std::size_t kMaxSodDesigns = 1;

/// The harness's folder with the other studies' plant files beside study ncs's (copied once).
const std::string& folder() {
  static const std::string dir = [] {
    const std::string d = oneshot::fuzz::study_folder(ONESHOT_NCS_PLANT_FILE);
    for (const char* f : {"sinopoli_dropping.json", "send_on_delta_oscillator.json", "hdd_numre.json", "reference_board.json"})
      std::filesystem::copy_file(std::string(ONESHOT_PLANTS_DIR) + "/" + f, d + "/" + f, std::filesystem::copy_options::overwrite_existing);
    return d;
  }();
  return dir;
}

/// How many of `n` scenarios run beside `approaches` approaches: kMaxRuns runs, at least one scenario.
std::size_t scenarios_kept(std::size_t n, std::size_t approaches) {
  return std::min(n, std::max<std::size_t>(1, kMaxRuns / approaches));
}

/// The summary's link counters add up: per approach and link, delivered + lost = sent.
void require_links_add_up(const nlohmann::json& summary, const std::string& what) {
  if (!summary.contains("links")) return;
  for (const auto& [approach, links] : summary.at("links").items())
    for (const auto& [link, c] : links.items())
      if (c.contains("sent") && c.contains("delivered") && c.contains("lost"))
        require(c.at("delivered").get<double>() + c.at("lost").get<double>() == c.at("sent").get<double>(),
                what + ": " + approach + ", link " + link + ": delivered + lost != sent");
}

/// A complete sweep; its summary (files in the folder's "out", no plots) finite or null, its
/// links adding up.
void require_summary(const e::SweepResults& r, st::SweepOutputs outputs, const std::string& what) {
  require(r.complete(), what + ": a run missing");
  const nlohmann::json j = outputs(r, folder() + "/out", false);
  require_finite_json(j, "summary", what);
  require_links_add_up(j, what);
}

/// Metric `m` of run (a, x) finite, `what` naming the study.
void require_finite_metric(const e::SweepResults& r, std::size_t a, std::size_t x, std::size_t m, const std::string& what) {
  require(std::isfinite(r.at(a, x, 0, m)), what + ": a non-finite " + r.spec.metrics[m] + " (" + r.spec.approaches[a] + " on " +
                                               r.spec.scenarios[x] + ")");
}

/// The sweep `run()`: its results, or none (0 runs) when it refuses with engine::InputError,
/// which must name a field (sod: a δt design that fails names 'plant.file').
template <class Run>
e::SweepResults swept(Run run, const std::string& what) {
  try {
    return run();
  } catch (const e::InputError& x) {
    require_named(x, what);
    return e::SweepResults{};
  }
}

/// The input `text` parsed with the study's `schema` and mapped by `map` (a copy the harness
/// cuts), or null when the parser (any refusal) or the mapping (naming the field) refuses it,
/// or, petc, when a scenario is longer than kMaxPetcSeconds.
template <class Study, class Map>
std::shared_ptr<Study> mapped(const std::string& text, const e::StudySchema& schema, Map map, const std::string& what) {
  e::StudyFile file;
  try {
    file = e::parse_study(text, folder() + "/fuzz.json", &schema, folder());
  } catch (const e::InputError&) {
    return nullptr;  // the parser's refusals: fuzz_study's
  }
  if constexpr (std::is_same_v<Study, st::PetcStudy>) {  // the petc design runs over the whole horizon: long files skipped
    double longest = file.duration_s;
    for (const e::ScenarioSpec& x : file.scenarios)
      if (x.duration_s) longest = std::fmax(longest, *x.duration_s);
    if (!(longest <= kMaxPetcSeconds)) return nullptr;
  }
  try {
    return std::make_shared<Study>(*map(file));
  } catch (const e::InputError& x) {
    require_named(x, what);
    return nullptr;
  }
}

/// A dropping file: the closed loop's runs cut at kMaxSteps steps.
void run_dropping(const std::string& text) {
  const std::shared_ptr<st::DroppingStudy> s = mapped<st::DroppingStudy>(text, st::dropping_schema(), st::map_dropping_study, "study run (dropping)");
  if (!s) return;
  const std::size_t na = std::min(s->approaches.size(), kMaxRuns), ns = scenarios_kept(s->scenarios.size(), na);
  s->approaches.resize(na);
  s->kinds.resize(na);
  s->runs.resize(na);
  s->scenarios.resize(ns);
  for (auto& per : s->runs) {
    per.resize(ns);
    for (oneshot::dropping::RunConfig& c : per) c.steps = std::min(c.steps, kMaxSteps);
  }
  const e::SweepResults r = swept([&] { return st::run_dropping_sweep(*s, 1, 1, e::Shard{}); }, "study run (dropping)");
  if (r.spec.runs() == 0) return;
  const std::size_t sent = r.metric("sent"), lost = r.metric("lost");
  for (std::size_t a = 0; a < na; ++a)
    for (std::size_t x = 0; x < ns; ++x) {
      // cost, err, trace_p: a diverging loop's are not finite (docs/study-files.md, "Study dropping");
      // gamma: the buffered filter's only (NaN otherwise: closed_loop.hpp); the counters always finite.
      for (const char* m : {"failed", "sent", "lost", "late", "refused"}) require_finite_metric(r, a, x, r.metric(m), "dropping");
      if (s->runs[a][x].estimator == oneshot::dropping::EstimatorKind::kBuffered) require_finite_metric(r, a, x, r.metric("gamma"), "dropping");
      require(r.at(a, x, 0, lost) <= r.at(a, x, 0, sent) && r.at(a, x, 0, sent) <= static_cast<double>(s->runs[a][x].steps) + 1,
              "dropping: lost ≤ sent ≤ steps + 1 fails on " + r.spec.approaches[a] + ", " + r.spec.scenarios[x]);
    }
  require_summary(r, st::dropping_run_outputs, "study run (dropping)");
}

/// A sod file: its runs (and its δt designs) cut at kMaxSteps steps.
void run_sod(const std::string& text) {
  const std::shared_ptr<st::SodStudy> s = mapped<st::SodStudy>(text, st::sod_schema(), st::map_sod_study, "study run (sod)");
  if (!s) return;
  const std::size_t na = std::min(s->approaches.size(), kMaxRuns), ns = scenarios_kept(s->scenarios.size(), na);
  s->approaches.resize(na);
  s->scenarios.resize(ns);
  for (st::SodScenario& x : s->scenarios) x.steps = std::min<std::int64_t>(x.steps, kMaxSteps);
  std::size_t designs = 0;  // msod's δt designs (each a bisection of DAREs: ~100 ms under ASan, whatever the steps)
  for (const st::SodApproach& a : s->approaches)
    for (const st::SodScenario& x : s->scenarios)
      designs += a.sender == oneshot::sod::SenderKind::kModifiedSod && !s->n_t_given && x.loss > 0 ? 1 : 0;
  if (designs > kMaxSodDesigns) return;
  const e::SweepResults r = swept([&] { return st::run_sod_sweep(*s, 1, 1, e::Shard{}); }, "study run (sod)");
  if (r.spec.runs() == 0) return;
  for (std::size_t a = 0; a < na; ++a)
    for (std::size_t x = 0; x < ns; ++x) {
      for (std::size_t m = 0; m < r.spec.metrics.size(); ++m) require_finite_metric(r, a, x, m, "sod");
      for (const char* i : {"1", "2"}) {
        const double sends = r.at(a, x, 0, r.metric(std::string("sends") + i)), lost = r.at(a, x, 0, r.metric(std::string("lost") + i));
        require(lost <= sends && sends <= static_cast<double>(s->scenarios[x].steps) + 1,
                std::string("sod: lost ≤ sent ≤ steps + 1 fails on link ") + i + ", " + r.spec.approaches[a] + ", " + r.spec.scenarios[x]);
      }
    }
  require_summary(r, st::sod_run_outputs, "study run (sod)");
}

/// A petc file of at most kMaxPetcSeconds (and mapped K ≤ kMaxSteps) per scenario.
void run_petc(const std::string& text) {
  const std::shared_ptr<st::PetcStudy> s = mapped<st::PetcStudy>(text, st::petc_schema(), st::map_petc_study, "study run (petc)");
  if (!s) return;
  for (const auto& setup : s->setups)
    if (setup.opt.steps > kMaxSteps) return;
  const std::size_t na = std::min(s->approaches.size(), kMaxRuns), ns = scenarios_kept(s->scenarios.size(), na);
  s->approaches.resize(na);
  s->kinds.resize(na);
  s->runs.resize(na);
  for (auto& per : s->runs) per.resize(ns);
  s->scenarios.resize(ns);
  s->setups.resize(ns);
  const e::SweepResults r = swept([&] { return st::run_petc_sweep(*s, 1, 1, e::Shard{}); }, "study run (petc)");
  if (r.spec.runs() == 0) return;
  for (std::size_t a = 0; a < na; ++a)
    for (std::size_t x = 0; x < ns; ++x)
      for (std::size_t m = 0; m < r.spec.metrics.size(); ++m) require_finite_metric(r, a, x, m, "petc");
  require_summary(r, st::petc_run_outputs, "study run (petc)");
}

/// A oneshot file: its scenarios cut at min(kMaxDurationS, kMaxPeriods h), at least h.
void run_oneshot(const std::string& text) {
  const std::shared_ptr<st::OneShotFileStudy> s =
      mapped<st::OneShotFileStudy>(text, st::oneshot_schema(), st::map_oneshot_study, "study run (oneshot)");
  if (!s) return;
  const std::size_t na = std::min(s->approaches.size(), kMaxRuns), ns = scenarios_kept(s->scenarios.size(), na);
  s->approaches.resize(na);
  s->kinds.resize(na);
  s->options.resize(na);
  s->settings.resize(na);
  s->scenarios.resize(ns);
  const double h_s = static_cast<double>(s->plant.period_us) * 1e-6;
  for (oneshot::sim::Scenario& x : s->scenarios) x.duration_s = std::fmin(x.duration_s, std::fmax(h_s, std::fmin(kMaxDurationS, kMaxPeriods * h_s)));
  const e::SweepResults r = swept([&] { return st::run_oneshot_sweep(*s, 1, 1, e::Shard{}); }, "study run (oneshot)");
  if (r.spec.runs() == 0) return;
  for (std::size_t a = 0; a < na; ++a)
    for (std::size_t x = 0; x < ns; ++x)
      for (std::size_t m = 0; m < r.spec.metrics.size(); ++m) require_finite_metric(r, a, x, m, "oneshot");
  require_summary(r, st::oneshot_run_outputs, "study run (oneshot)");
}

/// An ncs file (the loops of sim_host/ncs/), cut by cap_duration.
void run_ncs(const std::string& text, std::size_t size) {
  const std::string& dir = folder();
  e::StudyFile file;
  try {
    file = e::parse_study(text, dir + "/fuzz.json", &st::ncs_schema(), dir);
  } catch (const e::InputError&) {
    return;  // refused by the parser with a message (fuzz_study checks those): fine
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
    return;
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
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  e::StudyFile generic;  // its "study", as `study run` reads it
  try {
    generic = e::parse_study(text, folder() + "/fuzz.json", nullptr, folder());
  } catch (const e::InputError&) {
    return 0;
  }
  if (generic.study == "dropping") run_dropping(text);
  else if (generic.study == "sod") run_sod(text);
  else if (generic.study == "petc") run_petc(text);
  else if (generic.study == "oneshot") run_oneshot(text);
  else run_ncs(text, size);
  return 0;
}
