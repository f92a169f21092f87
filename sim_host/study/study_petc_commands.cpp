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

void petc_run_command(const PetcStudy& s, const PetcCommand& c) {
  if (c.analytic) throw engine::InputError("field '--analytic': no exact cost for the petc loop (its triggers run on what is measured)");
  if (c.max_duration) throw engine::InputError("field '--max-duration': a petc file's runs take its duration_s");
  const engine::Shard part = engine::parse_shard(c.shard);
  util::make_directory(c.out);
  const auto start = std::chrono::steady_clock::now();
  const engine::SweepResults r = run_petc_sweep(s, c.seeds, c.threads, part);
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  nlohmann::json j;
  if (!part.whole()) {
    j = engine::write_shard_file(r, c.out, "run", part);
  } else {
    j = petc_run_outputs(r, c.out, !c.no_plots);
    if (c.json != "-") std::cout << j.at("markdown").get<std::string>() << "order: " << j.at("order_text").get<std::string>() << "\n";
  }
  if (!c.json.empty()) util::write_json(c.json, j);
  if (c.json != "-") std::cout << "study run: " << r.spec.runs() << " runs, wall time " << wall << " s, written to " << c.out << "\n";
}

void petc_report_command(const PetcStudy& s, const nlohmann::json& resolution, const PetcCommand& c) {
  if (c.max_duration) throw engine::InputError("field '--max-duration': a petc file's runs take its duration_s");
  if (c.trace && c.trace_names.empty()) throw engine::InputError("field '--trace': an empty approach name");
  const std::vector<std::size_t> traced = trace_selection(s.approaches, s.source, c.trace_names);  // refused before writing
  util::make_directory(c.out);
  const engine::SweepResults r = run_petc_sweep(s, c.seeds, c.threads, engine::Shard{});
  nlohmann::json j = petc_run_outputs(r, c.out, !c.no_plots);
  for (const auto& f : write_petc_cost_plot(r, c.out, !c.no_plots)) j["files"].push_back(f);
  nlohmann::json traces = write_petc_traces(s, traced, c.out, !c.no_plots);
  for (std::size_t a : traced) {  // the traced run is the sweep's: the same GPI, bit for bit
    const std::string& an = r.spec.approaches[a];
    if (traces.contains(an)) traces[an]["same_cost_as_sweep"] = traces[an].at("cost").get<double>() == r.at(a, 0, 0, r.metric("cost"));
  }
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
