/// @file study_file_report.hpp
/// @brief `oneshot-sim study report FILE OUTDIR`: a study file's run as a markdown report
///        (OUTDIR/report.md), like the built-in studies' sections of `oneshot-sim report`.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "oneshot/engine/sweep.hpp"

namespace oneshot::study {

struct NcsStudy;

/// Default cap of `study report`'s traced runs without --trace: the first this many approaches.
inline constexpr std::size_t kMaxDefaultTraces = 10;

/// The approaches (indices into `s.approaches`) `study report` traces: those named in
/// `names` (comma-separated, as the report names them: I, S, AK, OSK, ...; each once), or,
/// when `names` is empty, the first kMaxDefaultTraces. engine::InputError naming the field
/// `--trace` for an empty or unknown name or one given twice.
std::vector<std::size_t> trace_selection(const NcsStudy& s, const std::string& names);

/// The same selection among `approaches` (any study's names, in its order) of the file `source`.
std::vector<std::size_t> trace_selection(const std::vector<std::string>& approaches, const std::string& source,
                                         const std::string& names);

/// Marks each traced approach of `traced` that has an entry in `traces` with
/// `same_cost_as_sweep`: its trace's "cost" (null when not finite) equal to the sweep's run of the
/// first scenario and the first seed, bit for bit (a null cost matches a non-finite run).
void mark_same_cost_as_sweep(nlohmann::json& traces, const engine::SweepResults& r, const std::vector<std::size_t>& traced);

/// One traced run per approach of `selected` on the first scenario and the first seed, the
/// same run as the sweep's (same seed and streams; the trace and the message log only
/// observe): OUT_DIR/trace_<A>_states.csv (t_s, x1, x2, r1, u: the plant's true states, the
/// set-point and the applied input every ms; runs past 5 s a coarser step, at most 5000 rows), trace_<A>_estimates.csv (t_s, xhat1,
/// xhat2: the controller's estimate at the instant it targets; only when the approach has
/// one), trace_<A>_messages.csv (leg, leg_index, sent_s, arrival_s, lost, delivered: every
/// message of the legs; arrival_s empty when there is none) and, with `plots`,
/// trace_<A>.png drawn by gnuplot (states, estimates and set-point; input; a time line of the
/// first periods with one arrow per delivered message from its sending to its arrival and a
/// cross per lost one). Returns per approach the files, the trace's cost, and the message
/// counts (sent, delivered, lost) per leg. `<A>` is the approach's name with '+' as "plus".
nlohmann::json write_traces(const NcsStudy& s, const std::vector<std::size_t>& selected, const std::string& out_dir,
                            bool plots);

/// The report's "Traces" section for `traces` (write_traces()'s result): what is drawn, then
/// per approach its plot (or its CSV files without plots) and its cost beside the sweep's for
/// the same run (`results`: first scenario, first seed).
std::string traces_markdown(const nlohmann::json& traces, const engine::SweepResults& results, bool plots);

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
