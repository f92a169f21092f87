/// @file studies.cpp
/// @brief The one list of the studies built into oneshot-sim, and what the CLI, `merge` and
///        `report` take from it.
///
/// A study lives in its own folder sim_host/<study>/ (sources, plant and scenario files,
/// experiments, plots, its CMakeLists.txt with oneshot_study()), defines its StudyDescriptor
/// once there, and is listed here. The engine (sim_host/engine/) knows no study.
#include <map>
#include <stdexcept>

#include "oneshot/sim/cli_commands.hpp"
#include "oneshot/sim/study_descriptor.hpp"

namespace oneshot::sim {

const std::vector<StudyDescriptor>& studies() {
  static const std::vector<StudyDescriptor> all = {oneshot_study(), ncs_study(),  dropping_study(),
                                                   sod_study(),     petc_study(), kernel_study(),
                                                   study_files_study()};
  return all;
}

void register_studies(CLI::App& app) {
  for (const StudyDescriptor& s : studies()) {
    CLI::App* group = app.add_subcommand(s.name, s.summary);
    group->require_subcommand(1);
    s.add_commands(group);
  }
}

const SweepSummarizer& find_summarizer(const std::string& study, const std::string& experiment) {
  std::map<std::string, const SweepSummarizer*> known;  // "study experiment", sorted for the message
  for (const StudyDescriptor& s : studies()) {
    for (const auto& [name, summarizer] : s.summarizers) known[s.name + " " + name] = &summarizer;
  }
  const auto it = known.find(study + " " + experiment);
  if (it != known.end()) return *it->second;
  std::string list;
  for (const auto& [k, v] : known) list += (list.empty() ? "" : ", ") + k;
  throw std::invalid_argument("no study experiment '" + study + " " + experiment + "' can merge sweeps (known: " + list +
                              ")");
}

}  // namespace oneshot::sim
