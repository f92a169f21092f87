/// @file simulation.hpp
/// @brief One closed-loop run of the one-shot study (seed 000): the board plant driving
///        the firmware's control task on the discrete-event engine.
///
/// The harness plays the board through the host port (hal/host_sim): at each actuation
/// instant it raises the timer interrupt of the task, at each sampling instant it sets
/// the clock, the ADC code (circuit output + measurement noise, 12-bit) and the
/// set-point, and calls the task's job; PWM writes go back into the board plant at the
/// instant the task model gives them effect (sim_host/oneshot/board_loop.hpp). Random
/// streams (jitter, measurement noise, set-points) are shared by every approach for a
/// given seed; process noise has its own stream, drawn once per physical event.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "oneshot/controller_design.hpp"
#include "oneshot/design/controller_synthesis.hpp"
#include "oneshot/design/plant_description.hpp"
#include "oneshot/design/table_builder.hpp"
#include "approach.hpp"
#include "board_config.hpp"
#include "scenario.hpp"

namespace oneshot::sim {

/// Φ/Γ/Q_d source of the one-shot filters.
enum class DiscretizerKind : std::uint8_t {
  kTable,    ///< Look-up table, exact between grid points.
  kNearest,  ///< Look-up table at the nearest grid point (the original design).
  kGeneric,  ///< Matrix exponentials at every call.
};

/// Number format of the control job.
enum class NumberFormat : std::uint8_t {
  kFloat,   ///< IEEE single, as on an MCU without double support.
  kDouble,  ///< IEEE double (the oracle).
  kFixed,   ///< The design step's Q formats (built-in plant, or one compiled in with ONESHOT_PLANT).
  kQ15,     ///< Approach B as the generated q15 C99 job (oneshot_job.c); the other approaches in double.
  kFloatPoly,  ///< Approach B as the generated float_poly C99 job (oneshot_job.c); the others in double.
};

/// Name of a number format ("float", "double", "fixed", "q15", "float_poly").
const char* to_string(NumberFormat f);
/// The number format called `name` (its to_string), or nothing.
std::optional<NumberFormat> number_format_named(const std::string& name);
/// Every number format's name, in declaration order.
std::vector<std::string> number_format_names();
/// Name of a discretizer ("table", "nearest", "generic").
const char* to_string(DiscretizerKind d);
/// The discretizer called `name` (its to_string), or nothing.
std::optional<DiscretizerKind> discretizer_named(const std::string& name);
/// Every discretizer's name: table, nearest, generic.
std::vector<std::string> discretizer_names();

/// Options of one run.
struct RunOptions {
  Approach approach = Approach::kB;                 ///< Approach A–E.
  DiscretizerKind discretizer = DiscretizerKind::kTable;  ///< Table or generic routine.
  NumberFormat format = NumberFormat::kFloat;       ///< Scalar of the job (float: as on the MCU).
  NoiseModel noise = NoiseModel::kExact;            ///< Constant Q or exact Q_d(τ).
  BoardOptions board;                               ///< Emulator options.
  double p0_scale = 1.0;                            ///< Initial covariance = p0_scale · P0.
  bool record_jobs = false;                         ///< Keep one record per job.
  class PilLink* pil = nullptr;                     ///< Run the job in the emulated MCU (pil_link.hpp).
  std::int32_t trace_step_us = 0;                   ///< Dense state trace step (0: none).
};

/// One job as the harness saw it.
struct JobRecord {
  double t_sample_s = 0;          ///< Sampling instant.
  std::int32_t tau_us = 0;        ///< τ the job used.
  double y_volts = 0;             ///< Measured value (ADC code converted).
  std::vector<double> x_true;     ///< True state at the sampling instant.
  std::vector<double> estimate;   ///< Estimator output (at the actuation instant it prepares).
  double gain0 = 0;               ///< First element of the Kalman gain (0 without filter).
  double setpoint_volts = 0;      ///< Reference the job used.
  double u_volts = 0;             ///< Commanded input from this job.
  std::int32_t y_code = 0;        ///< ADC code the job read.
  std::int32_t setpoint_code = 0; ///< Set-point code the job read.
  double t_apply_s = 0;           ///< Instant the job's output takes effect (one-shot: t_k).
};

/// A point of the dense state trace.
struct TracePoint {
  double t_s = 0;              ///< Time.
  std::vector<double> x;       ///< True state.
  double setpoint_volts = 0;   ///< Reference.
  double u_volts = 0;          ///< Commanded input.
};

/// Outcome of one run.
struct RunResult {
  CostBreakdown cost;              ///< J = ∫ eᵀQ1c e + ṽᵀQ2c ṽ dt over the run.
  double duration_s = 0;           ///< Simulated time.
  std::uint32_t jobs = 0;          ///< Jobs run.
  std::uint32_t overruns = 0;      ///< Actuation instants without a prepared value.
  std::uint32_t faults = 0;        ///< Jobs whose maths was not exact (clamped τ, …).
  bool saturated = false;          ///< The fixed-point saturation flag was raised.
  std::vector<JobRecord> job_records;  ///< When requested.
  std::vector<TracePoint> trace;       ///< When requested.
  std::uint64_t events = 0;            ///< Engine events run.
};

/// Plant, design and tables shared (read-only) by every run of an experiment.
class SimContext {
 public:
  /// The built-in reference board: the controller uses the generated header (the
  /// firmware's own constants, patterns and table).
  static std::shared_ptr<const SimContext> reference();
  /// A plant from a file: design and tables built at run time (dense structure).
  static std::shared_ptr<const SimContext> from_plant(design::PlantDescription plant);
  /// Reference when `path` is empty, else the file.
  static std::shared_ptr<const SimContext> load(const std::string& path);

  const design::PlantDescription& plant() const { return plant_; }    ///< Plant.
  const design::DesignResult& design() const { return design_; }      ///< Design.
  bool generated() const { return generated_; }                       ///< Uses the generated header.
  const design::TableData<float>& table_float() const { return table_float_; }    ///< Run-time table.
  const design::TableData<double>& table_double() const { return table_double_; } ///< Run-time table.

 private:
  design::PlantDescription plant_;
  design::DesignResult design_;
  bool generated_ = false;
  design::TableData<float> table_float_;
  design::TableData<double> table_double_;
};

/// False when the plant's design cannot run approach `a` (E without a deadbeat observer).
bool approach_available(const SimContext& ctx, Approach a);

/// Runs `scenario` with `seed` under `options`; std::invalid_argument naming the reason
/// when the approach is unavailable for the plant.
RunResult simulate(const SimContext& ctx, const Scenario& scenario, std::uint64_t seed, const RunOptions& options);

/// Builds the control job of `options` and calls use(replay); each replay() restores the
/// initial controller and runs the recorded jobs (τ, ADC and set-point codes) in order.
void with_job_replay(const SimContext& ctx, const RunOptions& options, const std::vector<JobRecord>& jobs,
                     const std::function<void(const std::function<void()>&)>& use);

}  // namespace oneshot::sim
