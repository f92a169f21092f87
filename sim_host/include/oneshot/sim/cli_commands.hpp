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

/// Every study under `oneshot-sim <study> <experiment>` (sim_host/src/studies.cpp).
void register_studies(CLI::App& app);

/// `oneshot <experiment>`: the one-shot study, seed 000 (sim_host/oneshot/).
void register_oneshot_study(CLI::App& app);

/// `ncs <experiment>`: networked actuation sync, seed 001 (sim_host/ncs/).
void register_ncs_study(CLI::App& app);

/// `dropping <experiment>`: the over-delay dropping Kalman study, seed 002 (sim_host/dropping/).
void register_dropping_study(CLI::App& app);

/// `sod <experiment>`: send-on-delta estimation, seed 004 (sim_host/sod/).
void register_sod_study(CLI::App& app);

/// `petc <experiment>`: NUMRE periodic event-triggered control, seed 003 (sim_host/petc/).
void register_petc_study(CLI::App& app);

/// `oneshot-sim kernel analyze|simulate`: task sets on the engine's CPU model (sim_host/kernel/).
void register_kernel_study(CLI::App& app);

}  // namespace oneshot::sim
