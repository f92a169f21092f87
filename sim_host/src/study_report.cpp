/// @file study_report.cpp
/// @brief Registry of the studies' report sections (see study_report.hpp).
#include "oneshot/sim/study_report.hpp"

#include <stdexcept>
#include <utility>

namespace oneshot::sim {
namespace {

std::vector<StudyReportSection>& sections() {
  static std::vector<StudyReportSection> s;
  return s;
}

}  // namespace

void add_study_report_section(StudyReportSection section) {
  if (section.study.empty() || !section.run) throw std::invalid_argument("study report section needs a name and a function");
  for (const StudyReportSection& s : sections()) {
    if (s.study == section.study) throw std::invalid_argument("study report section registered twice: " + section.study);
  }
  sections().push_back(std::move(section));
}

const std::vector<StudyReportSection>& study_report_sections() { return sections(); }

}  // namespace oneshot::sim
