/// @file study_report.hpp
/// @brief The studies' sections of the main report (`oneshot-sim report`).
///
/// Each study registers one section when it registers its commands
/// (register_<study>_study in sim_host/src/studies.cpp). `report` runs study 000 first,
/// then every registered section in registration order on its built-in defaults, each
/// writing its files under OUTDIR/<study>/ and returning its markdown and JSON.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
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

/// Adds a section (called from register_<study>_study); a second section for the same study is refused.
void add_study_report_section(StudyReportSection section);

/// The registered sections, in registration order.
const std::vector<StudyReportSection>& study_report_sections();

}  // namespace oneshot::sim
