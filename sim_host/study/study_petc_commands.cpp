/// @file study_petc_commands.cpp
/// @brief `study run`, `study report` and `study bench` of a "study": "petc" file (see study_petc_study.hpp).
#include <chrono>
#include <filesystem>
#include <iostream>

#include "oneshot/engine/json_fields.hpp"
#include "oneshot/engine/sweep.hpp"
#include "oneshot/util/output_files.hpp"
#include "study_bench.hpp"
#include "study_check.hpp"
#include "study_file_report.hpp"
#include "study_petc_study.hpp"

namespace oneshot::study {

void petc_report_command(const PetcStudy& s, const nlohmann::json& resolution, const PetcCommand& c) {
  if (c.max_duration) throw engine::InputError("field '--max-duration': a petc file's runs take its duration_s");
  if (c.trace && c.trace_names.empty()) throw engine::InputError("field '--trace': an empty approach name");
  const std::vector<std::size_t> traced = trace_selection(s.approaches, s.source, c.trace_names);  // refused before writing
  util::make_directory(c.out);
  const engine::SweepResults r = run_petc_sweep(s, c.seeds, c.threads, engine::Shard{});
  nlohmann::json j = petc_run_outputs(r, c.out, !c.no_plots);
  for (const auto& f : write_petc_cost_plot(r, c.out, !c.no_plots)) j["files"].push_back(f);
  nlohmann::json traces = write_petc_traces(s, traced, c.out, !c.no_plots);
  mark_same_cost_as_sweep(traces, r, traced);
  j["traces"] = traces;
  nlohmann::json ran = resolution;  // the grid that ran: --seeds overrides the file's count
  ran["seeds"]["count"] = r.spec.seeds;
  ran["grid"]["runs"] = r.spec.runs();
  const std::string text = describe_resolution(ran) + describe_petc(ran);
  const std::string md = petc_report_markdown(s, c.file, text, r, j, c.no_plots ? "" : "table.png", traces, !c.no_plots);
  util::write_text((std::filesystem::path(c.out) / "report.md").string(), md);
  util::write_json((std::filesystem::path(c.out) / "report.json").string(), j);
  std::cout << "study report: " << r.spec.runs() << " runs, written to " << (std::filesystem::path(c.out) / "report.md").string() << "\n";
}

}  // namespace oneshot::study
