/// @file cli_commands.hpp
/// @brief Subcommands of oneshot-sim; each registers itself on the CLI11 application.
#pragma once

#include <CLI/CLI.hpp>

namespace oneshot::sim {

/// `design [--plant FILE] [--json PATH|-]`: the design in text and JSON.
void register_design_command(CLI::App& app);

/// noise, jitter, gain, table1, exectime, run, benchmark, report.
void register_experiment_commands(CLI::App& app);

/// `merge SHARD...`: joins the shard files of a sweep (any study) into its result.
void register_merge_command(CLI::App& app);

/// Every study of sim_host/src/studies.cpp as `oneshot-sim <study> <experiment>`.
void register_studies(CLI::App& app);

}  // namespace oneshot::sim
