/// @file study_file_report.hpp
/// @brief `oneshot-sim study report FILE OUTDIR`: a study file's run as a markdown report
///        (OUTDIR/report.md), like the built-in studies' sections of `oneshot-sim report`.
#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "oneshot/engine/sweep.hpp"

namespace oneshot::study {

/// The report of a complete `study run` sweep: the file's name, `resolution_text` (what
/// `study check` prints), the cost table with 95 % intervals and ratios to I (the ncs report
/// section's code, ncs::table_section_markdown), every paired difference, the per-scenario
/// ratios and the per-link counters. `outputs` is run_outputs() of `results`; `plot_path`
/// (empty: none) is the cost bar plot, relative to the report; `simulated_time_text` says each
/// scenario's simulated time as run (after a --max-duration cap).
std::string report_markdown(const std::string& file, const std::string& resolution_text,
                            const std::string& simulated_time_text, const engine::SweepResults& results,
                            const nlohmann::json& outputs, const std::string& plot_path);

}  // namespace oneshot::study
