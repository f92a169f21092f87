/// @file study_ncs_scenario_map.hpp
/// @brief A scenario of a study file with "study": "ncs" mapped onto an ncs Scenario (its
///        set-point, noise, legs, the sensor's trigger and the controller's phase), refused
///        naming the field where the loop cannot run it, and where the approach that leads the
///        ratios (I, or IK for a plant of n > 6) would cost exactly 0 on it.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "ncs_model.hpp"
#include "oneshot/engine/study_file.hpp"
#include "study_ncs_runner.hpp"

namespace oneshot::study {

/// What a scenario takes from the file's nodes and approaches, which map_ncs_study() maps
/// before its scenarios.
struct NcsScenarioInputs {
  std::vector<double> sod_delta;                ///< The sensor's send-on-delta thresholds, one per output (empty: none).
  std::uint32_t sod_time_steps = 0;             ///< Its send-on-delta time_steps.
  std::optional<engine::TriggerSpec> mtm_rule;  ///< The sensor's MTM trigger (none: none).
  std::int64_t phase_us = 0;                    ///< The one-shot controller's phase φ (its timer at kh + φ), µs.
  /// The one-shot filters' Φ(h), Γ(h), Q_d(h) (index in ncs::kOneShotApproaches; null when not run).
  std::array<std::shared_ptr<const ncs::OneShotTriple>, ncs::kOneShotApproaches.size()> one_shot_triples{};
};

/// Why the approach `leading` (the first, the reference of every ratio: I, or IK for a plant of
/// n > 6) would cost exactly 0 on `sc` ("" when it does not); ratios to it would divide by 0. A
/// loop without delay that starts on the set-point costs nothing until the set-point first
/// changes (a square wave at T_r/2), and nothing at all when it never does, unless noise moves
/// it: I runs without noise (at cost 0 whenever the set-point does not change within the run);
/// IK runs the plant's process noise Q_c · noise_scale (at cost 0 then only with noise_scale 0:
/// with noise, amplitude 0 is a regulation study, the loop holding 0 against the noise).
std::string zero_reference_cost(const ncs::Context& ctx, const ncs::Scenario& sc, ncs::Approach leading);

/// Scenario `i` of `file` on the loop of `study` (its ctx and approaches mapped) with `in`;
/// engine::InputError naming the field (without the file's name) for a parameter out of range
/// or missing, a set-point off the period grid, a run shorter than one period h, a scenario on
/// which the leading approach would cost 0 (zero_reference_cost()), and S+'s or AKl's design
/// failing on it.
ncs::Scenario map_ncs_scenario(const engine::StudyFile& file, std::size_t i, const NcsStudy& study, const NcsScenarioInputs& in);

}  // namespace oneshot::study
