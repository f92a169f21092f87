/// @file study_sod_study.hpp
/// @brief A "study": "sod" file resolved (study_sod_map.cpp): its plant sampled at T, the two
///        sensor nodes' thresholds, per approach the sender rule and filter, per scenario the loss
///        rate ξ, the step input and the steps; the δt design of modified send-on-delta; what the
///        runner, the report and the bench of such a file share.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "oneshot/engine/sweep.hpp"
#include "sod_design.hpp"
#include "sod_model.hpp"
#include "sod_sim.hpp"

namespace oneshot::study {

/// One approach of a sod file: a configuration of the sod table.
struct SodApproach {
  std::string name;                                 ///< The file's name.
  std::string kind;                                 ///< sod-held, sod-kf, msod, periodic.
  sod::SenderKind sender = sod::SenderKind::kSod;   ///< Its sender rule (both nodes).
  sod::FilterKind filter = sod::FilterKind::kHeld;  ///< Its estimator.
  double mu = 5;                                    ///< msod, n_t designed: the bound factor μ.
  std::uint32_t every = 1;                          ///< periodic: every n-th sample.
};

/// One scenario of a sod file.
struct SodScenario {
  std::string name;        ///< The file's name.
  double loss = 0;         ///< ξ of both links (Bernoulli).
  double amplitude = 1;    ///< Step input u(t) = amplitude.
  std::int64_t steps = 0;  ///< N = duration_s / T.
};

/// A sod file resolved (map_sod_study()).
struct SodStudy {
  std::string source;                                ///< The study file.
  std::string plant_path;                            ///< Its plant file (resolved).
  sod::SodModel model;                               ///< The plant sampled at T.
  std::array<std::string, sod::kNodes> sensors;      ///< Sensor node i reads output y_i (file order).
  std::string estimator;                             ///< The controller node (the receiver and estimator).
  std::array<std::string, sod::kNodes> links;        ///< Link i runs from sensor i to the estimator.
  std::array<double, sod::kNodes> delta_y{};         ///< δy,i (nodes[].trigger.delta).
  bool n_t_given = false;                            ///< msod's n_t from nodes[].trigger.time_steps (else the design).
  std::array<std::uint32_t, sod::kNodes> n_t{};      ///< The given n_t.
  std::vector<SodApproach> approaches;               ///< In the file's order.
  std::vector<SodScenario> scenarios;                ///< In the file's order.
  std::uint64_t first_seed = 1;                      ///< First seed.
  std::size_t seeds = 0;                             ///< The file's count.
};

/// The resolved δt design of a sweep with `seeds` seeds: per approach and scenario the n_t
/// that runs (msod: given, or δt*/T of the §5 design at ξ of the scenario; 0 at ξ = 0 and for
/// the other kinds), and per designed (approach, scenario) the design's JSON.
struct SodDesigns {
  std::vector<std::vector<std::array<std::uint32_t, sod::kNodes>>> n_t;  ///< [approach][scenario].
  nlohmann::json json = nlohmann::json::array();                          ///< The designs that ran.
};

/// The δt designs of `s` for a sweep of `seeds` seeds from its first seed (0: the file's count)
/// on `threads` threads: ΔT_i measured as `sod design` measures it (lossless plain SOD at the
/// scenario's amplitude and steps, N T / packets_i, mean over the seeds), then
/// sod::design_delta_t() at ξ, δy and μ of the approach; as `oneshot-sim sod table` does.
SodDesigns sod_designs(const SodStudy& s, std::size_t seeds, unsigned threads);

/// The run of approach `a`, scenario `x` with the designs `d`.
sod::RunConfig sod_run_config(const SodStudy& s, const SodDesigns& d, std::size_t a, std::size_t x);

/// The settings of a run as JSON (the sweep's configuration: what a shard must agree on).
nlohmann::json sod_run_json(const sod::RunConfig& c);

/// The sweep of `s` for `experiment` ("run-sod", "bench-sod"): its approaches, scenarios, first
/// seed and `seeds` seeds (0: the file's count); metrics and config the caller's.
engine::SweepSpec sod_sweep_spec(const SodStudy& s, std::size_t seeds, const char* experiment);

}  // namespace oneshot::study
