/// @file sweep_parts.hpp
/// @brief What the dropping study's sweeps (experiments.cpp, hold_experiment.cpp) share: the
///        end of a sweep (shard file or summary), a cell's values over the seeds, the plant's
///        digest in the configuration and a faulted run's counters.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "closed_loop.hpp"
#include "experiments.hpp"
#include "oneshot/engine/random_stream.hpp"
#include "oneshot/engine/sweep.hpp"
#include "oneshot/sim/sweep_faults.hpp"
#include "oneshot/util/output_files.hpp"

namespace oneshot::dropping {

/// The sweep `r` of `experiment` done: its shard file when `opt` names a shard, else its summary
/// by `outputs` (files in opt.out_dir).
inline nlohmann::json finish(const engine::SweepResults& r, const StudyOptions& opt, const std::string& experiment,
                             nlohmann::json (*outputs)(const engine::SweepResults&, const std::string&, bool)) {
  if (!opt.shard.whole()) return engine::write_shard_file(r, opt.out_dir, experiment, opt.shard);
  util::make_directory(opt.out_dir);
  return outputs(r, opt.out_dir, opt.plots);
}

/// Metric `m` of approach `a` in scenario `s`, one value per seed.
inline std::vector<double> cell(const engine::SweepResults& r, std::size_t a, std::size_t s, std::size_t m) {
  std::vector<double> v(r.spec.seeds);
  for (std::size_t k = 0; k < r.spec.seeds; ++k) v[k] = r.at(a, s, k, m);
  return v;
}

/// The plant's identity in a sweep's configuration (a hash of its file, or of its name and source).
inline std::string plant_digest(const DroppingPlant& p) {
  char b[20];
  std::snprintf(b, sizeof b, "%016llx",
                static_cast<unsigned long long>(engine::stream_id(p.plant.source == "built-in sinopoli_dropping.json"
                                                                      ? dropping_plant_json()
                                                                      : p.plant.name + p.plant.source)));
  return b;
}

/// A faulted run's counters, with its cost over the clean run's of the same seed (run here).
inline std::vector<double> with_faults(std::vector<double> v, const DroppingPlant& plant, RunConfig c,
                                       const RunMetrics& m, std::uint64_t seed) {
  if (c.faults.empty()) return v;
  sim::RunFaultCounts f;
  f.injected = static_cast<double>(m.injected.injected());
  f.corrupt = m.corrupt;
  f.refused_non_finite = m.refused_non_finite;
  f.refused_sequence = m.refused_sequence;
  f.stale = m.stale;
  f.estimator_resets = m.estimate_non_finite;
  c.faults = engine::FaultSpec{};
  c.trace = false;
  f.ratio_to_clean = m.cost / run_closed_loop(plant, c, seed).cost;
  sim::append_fault_values(v, f);
  return v;
}

}  // namespace oneshot::dropping
