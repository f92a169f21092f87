/// @file study_dropping_study.hpp
/// @brief A "study": "dropping" file resolved (study_dropping_map.cpp): its plant and design, per
///        approach and scenario the closed loop's settings; what the runner, the report and the
///        bench of such a file share.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "closed_loop.hpp"
#include "dropping_plant.hpp"
#include "oneshot/engine/sweep.hpp"

namespace oneshot::study {

/// A dropping file resolved (map_dropping_study()).
struct DroppingStudy {
  std::string source;                                  ///< The study file.
  std::string plant_path;                              ///< Its plant file (resolved).
  dropping::DroppingPlant plant;                       ///< Plant and design.
  std::string link;                                    ///< The file's name of the link.
  std::vector<std::string> approaches;                 ///< Names, in the file's order.
  std::vector<std::string> kinds;                      ///< Their kinds.
  std::vector<std::string> scenarios;                  ///< Names.
  std::vector<std::vector<dropping::RunConfig>> runs;  ///< [approach][scenario] the run's settings.
  std::uint64_t first_seed = 1;                        ///< First seed.
  std::size_t seeds = 0;                               ///< The file's count.
};

/// The settings of a run as JSON (the sweep's configuration: what a shard must agree on):
/// estimator, steps, the square wave, t_hold or r, the channel (bernoulli and its lambda, or the
/// link's delay, loss and order).
nlohmann::json dropping_run_json(const dropping::RunConfig& c);

/// The sweep of `s` for `experiment` ("run-dropping", "bench-dropping"): its approaches,
/// scenarios, first seed and `seeds` seeds (0: the file's count); metrics and config the caller's.
engine::SweepSpec dropping_sweep_spec(const DroppingStudy& s, std::size_t seeds, const char* experiment);

}  // namespace oneshot::study
