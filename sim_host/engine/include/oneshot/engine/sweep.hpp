/// @file sweep.hpp
/// @brief Monte Carlo sweeps: approaches × scenarios × seeds on every core, split into
///        shards that merge to the same result, byte for byte, as one run.
///
/// A sweep is fixed by its SweepSpec: names of the approaches, scenarios and per-run
/// metrics, the seeds, and `config`, a JSON object holding everything else that decides
/// the numbers (options, scenario definitions, plant digest). Run r = (a·S + s)·K + k runs
/// approach a on scenario s with seed first_seed + k and returns one value per metric.
/// Every approach of a scenario and seed sees the same random draws (the studies seed
/// every stream from (seed, stream name)), so approaches can be compared pairwise.
///
/// Results land by run index, whatever the thread that computed them, so the output is
/// the same for any thread count. Shard i/N owns the runs r with r mod N = i (round
/// robin: every shard gets a mix of cheap and expensive runs); its file holds the spec and
/// its runs' values (JSON numbers round-trip exactly), and merge_shards() checks the specs
/// agree and every run is present exactly once before the summary is computed from the
/// same values in the same order as a single run would.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace oneshot::engine {

/// Which part of a sweep a process runs (index/count; 0/1 is the whole sweep).
struct Shard {
  std::size_t index = 0;  ///< This shard, 0 … count − 1.
  std::size_t count = 1;  ///< Number of shards.
  /// True when run r belongs to this shard.
  bool owns(std::size_t r) const { return r % count == index; }
  /// True for the whole sweep.
  bool whole() const { return count == 1; }
};

/// Parses "i/N" (0 ≤ i < N ≤ 100000); std::invalid_argument naming `--shard` otherwise.
Shard parse_shard(const std::string& text);

/// The definition of a sweep.
struct SweepSpec {
  std::string study;                    ///< Study name ("oneshot", "ncs", …).
  std::string experiment;               ///< Experiment name ("table1", …).
  std::vector<std::string> approaches;  ///< Approach names, in table order.
  std::vector<std::string> scenarios;   ///< Scenario names.
  std::uint64_t first_seed = 1;         ///< Seed of k = 0.
  std::size_t seeds = 0;                ///< Seeds per (approach, scenario).
  std::vector<std::string> metrics;     ///< Per-run metric names.
  nlohmann::json config = nlohmann::json::object();  ///< Everything else that fixes the numbers.

  /// Number of runs.
  std::size_t runs() const { return approaches.size() * scenarios.size() * seeds; }
  /// Run index of (approach a, scenario s, seed index k).
  std::size_t run_index(std::size_t a, std::size_t s, std::size_t k) const { return (a * scenarios.size() + s) * seeds + k; }
  /// The spec as JSON (the shard files' header).
  nlohmann::json to_json() const;
  /// Spec from JSON (std::invalid_argument naming the field).
  static SweepSpec from_json(const nlohmann::json& j);
};

/// Values of a sweep's runs (all of them, or one shard's).
struct SweepResults {
  SweepSpec spec;                 ///< What ran.
  Shard shard;                    ///< Which part.
  std::vector<double> values;     ///< runs × metrics, row-major.
  std::vector<std::uint8_t> done; ///< Per run: 1 when its values are present.

  /// Value of metric m in run r.
  double at(std::size_t r, std::size_t m) const { return values[r * spec.metrics.size() + m]; }
  /// Value of metric m for (approach a, scenario s, seed index k).
  double at(std::size_t a, std::size_t s, std::size_t k, std::size_t m) const { return at(spec.run_index(a, s, k), m); }
  /// Index of the metric called `name` (std::invalid_argument otherwise).
  std::size_t metric(const std::string& name) const;
  /// True when every run is present.
  bool complete() const;
};

/// One run: (approach index, scenario index, seed) → one value per metric.
using RunFunction = std::function<std::vector<double>(std::size_t approach, std::size_t scenario, std::uint64_t seed)>;

/// Runs the shard's runs of `spec` on `threads` threads (0: every core) with a progress
/// bar labelled `label`; rethrows the first failure.
SweepResults run_sweep(const SweepSpec& spec, const Shard& shard, unsigned threads, const RunFunction& run,
                       const std::string& label);

/// The shard file: {"format": "oneshot-sweep-shard/1", "spec", "shard", "runs": [[r, v…]…]}.
nlohmann::json shard_to_json(const SweepResults& results);
/// Reads a shard file's JSON (std::invalid_argument naming the field).
SweepResults shard_from_json(const nlohmann::json& j);
/// Merges shards of one sweep; std::invalid_argument when their specs differ, a run is
/// missing or present twice.
SweepResults merge_shards(const std::vector<SweepResults>& shards);

/// Canonical file name of shard i/N of an experiment: "<experiment>.shard-<i>-of-<N>.json".
std::string shard_file_name(const std::string& experiment, const Shard& shard);

/// Writes the shard file of `results` (shard_to_json) as out_dir/shard_file_name(experiment,
/// shard), creating the folder, and returns its JSON.
nlohmann::json write_shard_file(const SweepResults& results, const std::string& out_dir, const std::string& experiment,
                                const Shard& shard);

}  // namespace oneshot::engine
