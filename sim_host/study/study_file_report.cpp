/// @file study_file_report.cpp
/// @brief The markdown of `oneshot-sim study report` (see study_file_report.hpp).
#include "study_file_report.hpp"

#include <cstdio>
#include <filesystem>
#include <sstream>
#include <vector>

#include "ncs_experiments.hpp"
#include "study_ncs_sweep.hpp"

namespace oneshot::study {

std::string report_markdown(const std::string& file, const std::string& resolution_text,
                            const std::string& simulated_time_text, const engine::SweepResults& results,
                            const nlohmann::json& outputs, const std::string& plot_path) {
  const engine::SweepSpec& spec = results.spec;
  std::vector<std::string> pairs;  // every pair, in the file's order of approaches
  for (std::size_t a = 0; a < spec.approaches.size(); ++a)
    for (std::size_t b = a + 1; b < spec.approaches.size(); ++b) pairs.push_back(spec.approaches[a] + "-" + spec.approaches[b]);
  std::ostringstream md;
  md << "## Study file `" << std::filesystem::path(file).filename().string() << "`\n\n"
     << "`oneshot-sim study report " << file << "`: " << spec.approaches.size() << " approaches x " << spec.scenarios.size()
     << " scenarios x " << spec.seeds << " seeds (first seed " << spec.first_seed
     << "), the same delay and noise draws for every approach (common random numbers).\n\n"
     << "### Configuration\n\nAs `oneshot-sim study check` resolves it:\n\n```text\n" << resolution_text << "```\n\n"
     << simulated_time_text << "\n\n"
     << "### Cost\n\n" << ncs::table_section_markdown(outputs, pairs, plot_path)
     << "Per scenario (mean cost of I, ratio of each approach's mean cost to I's):\n\n"
     << outputs.at("markdown_per_scenario").get<std::string>() << "\n### Links\n\n"
     << "Totals over every run: sent (handed to the link), delivered (not lost), lost (dropped by the loss model), "
        "late (dropped by the receiver as stale: not newer than what it holds, or after its period; the periods without a "
        "command are the late column of the cost table), refused (by the receiver's frame checks).\n\n"
     << "| approach | link |";
  for (const char* c : kLinkCounters) md << " " << c << " |";
  md << "\n|---|---|";
  for (std::size_t i = 0; i < std::size(kLinkCounters); ++i) md << "---|";
  md << "\n";
  const nlohmann::json& links = outputs.at("links");
  for (const std::string& a : spec.approaches) {
    for (const auto& l : spec.config.at("links")) {
      const nlohmann::json& e = links.at(a).at(l.get<std::string>());
      md << "| " << a << " | " << l.get<std::string>() << " |";
      for (const char* c : kLinkCounters) {
        char v[32];
        std::snprintf(v, sizeof v, " %.0f |", e.at(c).get<double>());
        md << v;
      }
      md << "\n";
    }
  }
  if (outputs.contains("markdown_cpu")) {
    const nlohmann::json& c = spec.config.at("controller_cpu");
    md << "\n### Controller CPU\n\nThe controller's job `" << c.at("job").get<std::string>() << "` on CPU `"
       << c.at("cpu").get<std::string>() << "` (" << c.at("scheduler").get<std::string>()
       << "): its response time tau_c over every run, beside the analysis's BCRT and WCRT; misses of the job and of the "
          "CPU's other tasks and ISRs; the CPU's busy time over the simulated time. I and IK do not use the CPU.\n"
       << outputs.at("markdown_cpu").get<std::string>();
  }
  return md.str();
}

}  // namespace oneshot::study
