/// @file study_descriptor.hpp
/// @brief One study of oneshot-sim, described once in its own folder: its command group, the
///        summarizers that let `merge` finish its sweeps, and its section of `report`.
///
/// sim_host/src/studies.cpp lists the descriptors; the CLI (`oneshot-sim <study> …`), `merge`
/// and `report` iterate that list, so adding a study is one descriptor and one line there.
#pragma once

#include <CLI/CLI.hpp>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "oneshot/engine/sweep.hpp"
#include "oneshot/sim/study_report.hpp"

namespace oneshot::sim {

/// Turns a complete (merged) sweep into the experiment's JSON summary and files in `out_dir`.
using SweepSummarizer = std::function<nlohmann::json(const engine::SweepResults& results, const std::string& out_dir, bool plots)>;

/// A study of oneshot-sim.
struct StudyDescriptor {
  std::string name;     ///< Command group `oneshot-sim <name>` and the study of its sweep specs.
  std::string summary;  ///< The group's line in `oneshot-sim --help`.
  std::function<void(CLI::App* group)> add_commands;      ///< Adds the study's experiments to its group.
  std::map<std::string, SweepSummarizer> summarizers;     ///< Experiment → finishes its merged sweeps.
  std::optional<StudyReportSection> report;               ///< Its section of `oneshot-sim report`, if any.
};

/// Every study, in the order of the CLI and of the report's sections (sim_host/src/studies.cpp).
const std::vector<StudyDescriptor>& studies();

/// The summarizer of (study, experiment); std::invalid_argument listing the known ones.
const SweepSummarizer& find_summarizer(const std::string& study, const std::string& experiment);

/// Study 000, the one-shot task model (sim_host/oneshot/).
StudyDescriptor oneshot_study();
/// Study 001, networked actuation sync (sim_host/ncs/).
StudyDescriptor ncs_study();
/// Study 002, the over-delay dropping Kalman filter (sim_host/dropping/).
StudyDescriptor dropping_study();
/// Study 004, send-on-delta estimation (sim_host/sod/).
StudyDescriptor sod_study();
/// Study 003, NUMRE periodic event-triggered control (sim_host/petc/).
StudyDescriptor petc_study();
/// CPUs, schedulers and response-time analysis of task files (sim_host/kernel/).
StudyDescriptor kernel_study();
/// Study files from the command line: `oneshot-sim study check|run FILE` (sim_host/study/).
StudyDescriptor study_files_study();

}  // namespace oneshot::sim
