/// @file study_report.hpp
/// @brief The studies' sections of the main report (`oneshot-sim report`).
///
/// A study names its section in its descriptor (study_descriptor.hpp). `report` runs study
/// 000 first, then every study's section in the order of sim_host/src/studies.cpp on its
/// built-in defaults, each writing its files under OUTDIR/<study>/ and returning its
/// markdown and JSON.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <ostream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace oneshot::sim {

/// What `report` passes to every study section.
struct StudyReportContext {
  std::string out_dir;    ///< The study's own folder (OUTDIR/<study>/), already created.
  std::string rel_dir;    ///< The same folder relative to report.md, for image links ("<study>").
  std::size_t threads = 0;  ///< Worker threads (0: all cores).
  std::uint64_t seed = 1;   ///< First seed.
  bool plots = true;        ///< Write PNG plots (gnuplot).
};

/// A section's output: markdown starting with a level-2 heading, and its JSON.
struct StudyReportResult {
  std::string markdown;
  nlohmann::json json;
};

/// One study's report section.
struct StudyReportSection {
  std::string study;  ///< Command name of the study, e.g. "ncs"; also its folder under OUTDIR.
  std::function<StudyReportResult(const StudyReportContext&)> run;  ///< Runs the study's defaults.
};

/// Runs every study's section in order, each in `report.out_dir`/<study>/ (created) with the
/// other fields of `report`; appends each markdown to `md` and returns {study: its JSON}.
nlohmann::json run_study_report_sections(const StudyReportContext& report, std::ostream& md);

}  // namespace oneshot::sim
