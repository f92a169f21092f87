/// @file linear_board.hpp
/// @brief Study 000 on a *linear board*: the board's continuous plant and timing (the same
///        jitter, set-point and noise streams as board_loop.hpp, so the same seed gives the same
///        timing draws), with the PWM replaced by its average (u applied as a real value) and the
///        ADC unquantized (y = C x + the board's measurement noise, a real value). The core
///        estimator and control law (what Controller::job runs, without the actuator's
///        quantization) run in double on these values.
///
/// Analytic mode: beside a noise-free run, the exact expected cost over the process and
/// measurement noise of that run's timing (linear_tracker.hpp). The run is refused (named
/// reason) when it leaves the linear regime: an input outside the actuator range (the board
/// would clamp), an estimator run that was not exact.
///
/// The linear board runs the compiled-in plant (the generated header's design in double).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "oneshot/engine/jump_linear_cost.hpp"
#include "scenario.hpp"
#include "simulation.hpp"

namespace oneshot::sim {

/// Refusal of the linear board's analytic mode: an input outside the actuator range.
inline constexpr const char* kLinearRefusalRange = "the noise-free input leaves the actuator range (the board clamps)";
/// An estimator run that was not exact (clamped τ, …).
inline constexpr const char* kLinearRefusalInexact = "an estimator run was not exact";
/// The tracker's mean left the simulated trajectory.
inline constexpr const char* kLinearRefusalMismatch = "the analytic mean left the simulated trajectory";

/// What a linear-board run does.
struct LinearOptions {
  bool noise = true;      ///< Process and measurement noise (the board's) in the model.
  bool analytic = false;  ///< Track E[J]: the simulated trajectory is then noise-free.
  bool record_jobs = false;  ///< Keep one LinearJobRecord per job.
};

/// Timing of one job of a linear-board run (as the emulated board's JobRecord has it).
struct LinearJobRecord {
  double t_sample_s = 0;    ///< Sampling instant.
  std::int32_t tau_us = 0;  ///< τ the job used.
};

/// Outcome of a linear-board run.
struct LinearRunResult {
  double cost = 0;                  ///< J of the simulated run (the noise path term as the board's: its expectation).
  engine::ExpectedCost analytic;    ///< E[J] over the noise (analytic mode).
  std::string refusal;              ///< Why the analytic value is refused ("" when it holds).
  double mismatch = 0;              ///< Largest |tracked mean − simulated| / max(1, |simulated|).
  std::uint32_t jobs = 0;           ///< Jobs run.
  std::uint32_t out_of_range = 0;   ///< Jobs whose input lay outside the actuator range (applied as is).
  std::uint32_t faults = 0;         ///< Estimator runs that were not exact.
  std::vector<LinearJobRecord> job_records;  ///< When requested (LinearOptions::record_jobs).
};

/// Runs `sc` with `seed` on the linear board: approach, discretizer, noise model, P0 scale and
/// board process-noise switch from `opt` (its number format is ignored: double). Throws
/// std::invalid_argument naming the reason for a run-time plant or an unavailable approach.
LinearRunResult run_linear_board(const SimContext& ctx, const Scenario& sc, std::uint64_t seed, const RunOptions& opt,
                                 const LinearOptions& lin);

}  // namespace oneshot::sim
