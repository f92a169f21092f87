/// @file cli_common.cpp
/// @brief The options every experiment command accepts (see cli_common.hpp).
#include "cli_common.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <memory>
#include <sstream>

#include "oneshot/util/output_files.hpp"
#include "oneshot/util/parallel.hpp"

namespace oneshot::sim::cli {

/// A finite number in [lo, hi] ((lo, hi] when lo_open): NaN, ±inf and text are refused by
/// name (CLI11's Range lets NaN through, which silently meant a default elsewhere).
CLI::Validator finite_in(double lo, double hi, bool lo_open) {
  std::ostringstream d;
  d << "FLOAT in " << (lo_open ? "(" : "[") << lo << ", " << hi << "]";
  return CLI::Validator(
      [=](std::string& text) -> std::string {
        char* end = nullptr;
        const double v = std::strtod(text.c_str(), &end);
        if (text.empty() || end == text.c_str() || *end != '\0') return "'" + text + "' is not a number";
        if (!std::isfinite(v)) return "must be a finite number, got '" + text + "'";
        if (v < lo || v > hi || (lo_open && v == lo)) {
          std::ostringstream o;
          o << "must be in " << (lo_open ? "(" : "[") << lo << ", " << hi << "], got " << text;
          return o.str();
        }
        return {};
      },
      d.str());
}

/// An unsigned decimal integer up to `max` (CLI11 reads "-1" into an unsigned as 2^64 - 1).
CLI::Validator unsigned_up_to(std::uint64_t max, const std::string& why) {
  return CLI::Validator(
      [=](std::string& text) -> std::string {
        const bool digits = !text.empty() && text.size() <= 19 &&
                            std::all_of(text.begin(), text.end(), [](char ch) { return ch >= '0' && ch <= '9'; });
        if (!digits || std::strtoull(text.c_str(), nullptr, 10) > max) {
          return "must be an integer in [0, " + std::to_string(max) + "] (" + why + "), got '" + text + "'";
        }
        return {};
      },
      "INT in [0, " + std::to_string(max) + "]");
}

void add_common(CLI::App* cmd, CliCommon& c, const std::string& default_out) {
  c.opt.out_dir = default_out;
  if (c.noise.empty()) c.noise = "exact";
  cmd->add_option("--plant", c.plant, "plant description JSON (default: the built-in reference board)")
      ->check(CLI::ExistingFile);
  cmd->add_option("--out", c.opt.out_dir, "output folder for CSV files and plots")->capture_default_str();
  cmd->add_option("--json", c.json, "write the summary as JSON to PATH ('-' for standard output)");
  cmd->add_option("--seed", c.opt.seed, "random seed (first seed of a sweep)")
      ->check(unsigned_up_to(kMaxSeed, "written exactly as a JSON/CSV number"))
      ->capture_default_str();
  cmd->add_option("--number-format", c.format,
                  "number format of the control job (q15: approach B as the generated 16-bit C99 job, "
                  "float_poly: as the generated float job with Phi/Gamma/Q_d polynomial in tau; the other "
                  "approaches in double)")
      ->check(CLI::IsMember(number_format_names()))
      ->capture_default_str();
  cmd->add_option("--discretizer", c.discretizer,
                  "Phi/Gamma/Qd of the one-shot filters: table (exact between grid points), nearest (table at "
                  "the nearest grid point, the original design) or generic (matrix exponentials)")
      ->check(CLI::IsMember(discretizer_names()))
      ->capture_default_str();
  cmd->add_option("--noise-model", c.noise, "process noise per prediction: exact Qd(tau) or the original constant Q")
      ->check(CLI::IsMember({"exact", "constant"}))
      ->capture_default_str();
  cmd->add_option("--pwm-update", c.pwm, "when a new duty acts: immediately or at the next PWM period")
      ->check(CLI::IsMember({"immediate", "period"}))
      ->capture_default_str();
  cmd->add_option("--threads", c.opt.threads, "worker threads for sweeps (0: every core)")
      ->check(unsigned_up_to(1024, "threads per process"))
      ->capture_default_str();
  cmd->add_flag("--no-plots", c.no_plots, "write CSV files only (no gnuplot)");
}

void emit(const CliCommon& c, const nlohmann::json& j) {
  if (!c.json.empty()) util::write_json(c.json, j);
  if (c.json != "-") {
    std::cout << j.value("experiment", std::string("result")) << ": written to " << c.opt.out_dir << "\n";
  }
}

/// Wall time and threads of a sweep, kept out of the deterministic results: OUT/timing.json.
void write_timing(const CommonOptions& o, const std::string& experiment, double wall_time_s) {
  util::write_json((std::filesystem::path(o.out_dir) / "timing.json").string(),
             {{"experiment", experiment}, {"wall_time_s", wall_time_s}, {"threads", util::worker_count(o.threads)}});
}

/// Adds experiment `name` with the common options (`default_out`, the noise model
/// `noise`: exact unless given) and a callback that loads the plant and calls `run`.
/// Returns the command, for the experiment's own options.
CLI::App* add_experiment(CLI::App& app, const std::string& name, const std::string& help,
                         const std::string& default_out, ExperimentRun run, const std::string& noise) {
  auto c = std::make_shared<CliCommon>();
  c->noise = noise;
  CLI::App* cmd = app.add_subcommand(name, help);
  add_common(cmd, *c, default_out);
  cmd->callback([c, run]() { run(*c, *SimContext::load(c->plant)); });
  return cmd;
}

std::vector<Scenario> scenarios_from(const std::string& path) { return path.empty() ? default_scenarios() : load_scenarios(path); }

std::string self_path() {
  std::error_code ec;
  const auto p = std::filesystem::read_symlink("/proc/self/exe", ec);
  return ec ? std::string() : p.string();
}

}  // namespace oneshot::sim::cli
