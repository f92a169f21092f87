/// @file study_report.cpp
/// @brief The studies' sections of the main report (see study_report.hpp).
#include "oneshot/sim/study_report.hpp"

#include <filesystem>
#include <iostream>
#include <utility>

#include "oneshot/sim/study_descriptor.hpp"
#include "oneshot/util/output_files.hpp"

namespace oneshot::sim {

nlohmann::json run_study_report_sections(const StudyReportContext& report, std::ostream& md) {
  nlohmann::json sections = nlohmann::json::object();
  for (const StudyDescriptor& study : studies()) {
    if (!study.report) continue;
    const StudyReportSection& section = *study.report;
    std::cerr << "report: " << section.study << "\n";
    StudyReportContext sc = report;
    sc.out_dir = (std::filesystem::path(report.out_dir) / section.study).string();
    sc.rel_dir = section.study;
    util::make_directory(sc.out_dir);
    StudyReportResult res = section.run(sc);
    md << res.markdown << "\n";
    sections[section.study] = std::move(res.json);
  }
  return sections;
}

}  // namespace oneshot::sim
