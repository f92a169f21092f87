/// @file ncs_faults.hpp
/// @brief `ncs faults`: the fault table of docs/faults.md, fault × node, from a command.
///
/// For every case (one fault spec aimed at one node: the frames it receives, or its
/// restart) the same seeds run clean and faulted (common random numbers: the faults draw
/// from their own streams). Per case: the runs whose cost is not finite (a poisoned
/// loop), the paired ratio J_fault,k / J_clean,k over the seeds where both are finite
/// (mean and 95 % Student-t interval), the faults injected and the node counters per run
/// beside the clean run's, and optionally the live figure: one `ncs live --inject` run
/// of the case, its live cost over the engine's cost of the same faulted seed.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "ncs_model.hpp"

namespace oneshot::ncs {

/// One row of the fault table.
struct FaultCase {
  std::string name;  ///< e.g. "nan sc".
  std::string node;  ///< The node that meets the fault ("controller": frames on sc, …).
  std::string spec;  ///< Fault spec (fault_spec.hpp).
};

/// The default rows for approach `a`: nan, flip, dup, replay, forge_seq on each of its
/// links, and a restart of each node.
std::vector<FaultCase> default_fault_cases(Approach a);

/// Options of `ncs faults`.
struct FaultTableOptions {
  Approach approach = Approach::kAK;  ///< Loop under test.
  Scenario scenario;                  ///< With its duration_s (the engine runs).
  std::size_t seeds = 50;             ///< Seeds (≥ 2).
  std::uint64_t first_seed = 1;       ///< Seed of the first replication.
  unsigned threads = 0;               ///< Worker threads (0: every core).
  std::vector<FaultCase> cases;       ///< Rows (empty: the defaults).
  double live_duration_s = 0;         ///< > 0: one live run per case of this length.
  std::string executable;             ///< oneshot-sim, for the live runs.
  std::string out_dir;                ///< Live runs go to OUT/live-<i>; the table to OUT/faults.md.
};

/// Runs the table; JSON with one entry per case and "markdown" (also OUT/faults.md).
nlohmann::json fault_table(const Context& ctx, const FaultTableOptions& o);

}  // namespace oneshot::ncs
