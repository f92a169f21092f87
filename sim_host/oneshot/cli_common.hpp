/// @file cli_common.hpp
/// @brief The options every experiment command of study 000 accepts (plant, output, seed,
///        number format, discretizer, noise model, PWM update, threads, plots), their
///        validators, and the helpers that write a command's results.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "oneshot_experiments.hpp"

namespace oneshot::sim::cli {

/// Options every experiment accepts.
struct CliCommon {
  std::string plant;                  ///< --plant ("" : the built-in reference board).
  std::string json;                   ///< --json ("" : none, "-" : standard output).
  CommonOptions opt;                  ///< --out, --seed, --threads as the experiments take them.
  std::string format = "float";       ///< --number-format.
  std::string discretizer = "table";  ///< --discretizer.
  std::string noise;  ///< --noise-model: set by add_common (exact) unless the command chose another default.
  std::string pwm = "immediate";      ///< --pwm-update.
  bool no_plots = false;              ///< --no-plots.

  /// The options as the experiments take them.
  CommonOptions resolve() const {
    CommonOptions o = opt;
    o.format = number_format_named(format).value_or(NumberFormat::kFloat);
    o.discretizer = discretizer_named(discretizer).value_or(DiscretizerKind::kTable);
    o.noise = noise == "constant" ? NoiseModel::kConstant : NoiseModel::kExact;
    o.board.update = pwm == "period" ? PwmUpdate::kNextPeriod : PwmUpdate::kImmediate;
    o.plots = !no_plots;
    return o;
  }
};

/// A finite number in [lo, hi] ((lo, hi] when lo_open): NaN, ±inf and text are refused by
/// name (CLI11's Range lets NaN through, which silently meant a default elsewhere).
CLI::Validator finite_in(double lo, double hi, bool lo_open = false);

/// An unsigned decimal integer up to `max` (CLI11 reads "-1" into an unsigned as 2^64 - 1).
CLI::Validator unsigned_up_to(std::uint64_t max, const std::string& why);

/// Largest seed: seeds are written to CSV and JSON as numbers, exact up to 2^53.
inline constexpr std::uint64_t kMaxSeed = std::uint64_t{1} << 53;

/// Adds the common options to `cmd`, stored in `c` (output folder `default_out`).
void add_common(CLI::App* cmd, CliCommon& c, const std::string& default_out);

/// Writes `j` where --json says and names the output folder on standard output (unless the
/// JSON goes there).
void emit(const CliCommon& c, const nlohmann::json& j);

/// Wall time and threads of a sweep, kept out of the deterministic results: OUT/timing.json.
void write_timing(const CommonOptions& o, const std::string& experiment, double wall_time_s);

/// What an experiment does with its options and the plant they name.
using ExperimentRun = std::function<void(const CliCommon& c, const SimContext& ctx)>;

/// Adds experiment `name` with the common options (`default_out`, the noise model
/// `noise`: exact unless given) and a callback that loads the plant and calls `run`.
/// Returns the command, for the experiment's own options.
CLI::App* add_experiment(CLI::App& app, const std::string& name, const std::string& help,
                         const std::string& default_out, ExperimentRun run, const std::string& noise = "");

/// The scenarios of file `path` (empty: the built-in ones).
std::vector<Scenario> scenarios_from(const std::string& path);

/// This program's path ("" when /proc/self/exe cannot be read).
std::string self_path();

}  // namespace oneshot::sim::cli
