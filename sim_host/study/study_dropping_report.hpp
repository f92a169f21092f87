/// @file study_dropping_report.hpp
/// @brief `oneshot-sim study report FILE OUTDIR` of a "study": "dropping" file: the report's
///        markdown, its cost plot and traced runs (docs/study-files.md, "Study dropping").
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "oneshot/engine/sweep.hpp"

namespace oneshot::study {

struct DroppingStudy;

/// Writes OUT_DIR/table_summary.csv (approach_index, mean, ci95, ratio_mean, ratio_ci95 of the
/// cost, over seeds of the scenario mean m_a,k = (1/S) Σ_s J_a,s,k; `nan` where a run diverged)
/// and, with `plots`, OUT_DIR/table.png drawn by gnuplot: one bar per approach at its mean cost
/// with its 95 % interval, the axis up to the highest interval's end (log scale when the largest
/// mean exceeds 100 × the smallest); an approach whose mean is not finite has no bar, its name
/// "(not finite)".
/// Returns the files written.
nlohmann::json write_dropping_cost_plot(const engine::SweepResults& results, const std::string& out_dir, bool plots);

/// One traced run per approach of `selected` on the first scenario and the first seed: the
/// sweep's run (same settings, same seed and streams; the trace only observes).
/// OUT_DIR/trace_<i>_<A>.csv (k, t_s, r, y, cx, cxhat, u, trace_p, err: the square wave r_k,
/// the sample y_k = C x_k + v_k the sensor sends, C x_k, C x̂(k|Y_k), u_k, tr P_k and
/// |x_k − x̂(k|Y_k)|² every step; runs of more than 5000 steps every ⌈steps/5000⌉-th step) and,
/// with `plots`, trace_<i>_<A>.png (output, estimate, samples and r; u; tr P and the squared
/// error). `<i>` is the approach's index from 1, `<A>` its name with every character outside
/// [A-Za-z0-9._-] as '_'. Returns per approach its files, the run's cost and the step.
nlohmann::json write_dropping_traces(const DroppingStudy& s, const std::vector<std::size_t>& selected,
                                     const std::string& out_dir, bool plots);

/// The report of a complete `study run` sweep of a dropping file: the file's name and grid,
/// `resolution_text` (what `study check` prints), the simulated time, the cost table with 95 %
/// intervals and ratios to the first approach (dropping_run_outputs()'s `outputs`), the order,
/// every paired difference, the plot `plot_path` (empty: none), the estimator's figures (mean
/// |x − x̂|², mean tr P, their ratio, γ beside λ_sys and λ_c), the link's counters, and the
/// traces `traces` (write_dropping_traces()'s result).
std::string dropping_report_markdown(const DroppingStudy& s, const std::string& file, const std::string& resolution_text,
                                     const engine::SweepResults& results, const nlohmann::json& outputs,
                                     const std::string& plot_path, const nlohmann::json& traces, bool plots);

}  // namespace oneshot::study
