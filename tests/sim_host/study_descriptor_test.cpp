/// @file study_descriptor_test.cpp
/// @brief The one list of studies: each study once, with its commands, summarizers and
///        report section, in the order the CLI and the report use.
#include <gtest/gtest.h>

#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "oneshot/sim/cli_commands.hpp"
#include "oneshot/sim/study_descriptor.hpp"

namespace oneshot::sim {
namespace {

TEST(StudyDescriptors, EveryStudyOnceInOrderWithItsCommands) {
  std::vector<std::string> names;
  for (const StudyDescriptor& s : studies()) {
    names.push_back(s.name);
    EXPECT_FALSE(s.summary.empty()) << s.name;
    ASSERT_TRUE(s.add_commands) << s.name;
    CLI::App group;
    s.add_commands(&group);
    EXPECT_FALSE(group.get_subcommands({}).empty()) << s.name << " adds no experiment";
  }
  EXPECT_EQ(names, (std::vector<std::string>{"oneshot", "ncs", "dropping", "sod", "petc", "kernel", "study"}));
}

TEST(StudyDescriptors, TheCliHasOneGroupPerStudy) {
  CLI::App app;
  register_studies(app);
  for (const StudyDescriptor& s : studies()) {
    const CLI::App* group = app.get_subcommand(s.name);
    EXPECT_EQ(group->get_description(), s.summary);
    EXPECT_EQ(group->get_require_subcommand_min(), 1U) << s.name;
  }
}

TEST(StudyDescriptors, ReportSectionsInOrderWithDistinctFolders) {
  std::vector<std::string> folders;
  for (const StudyDescriptor& s : studies()) {
    if (!s.report) continue;
    EXPECT_TRUE(s.report->run) << s.name;
    folders.push_back(s.report->study);
  }
  // Study 000's Table I and experiments open the report; its descriptor adds the kernel section.
  EXPECT_EQ(folders, (std::vector<std::string>{"kernel", "ncs", "dropping", "sod", "petc"}));
}

TEST(StudyDescriptors, MergeFindsEverySummarizerAndNamesTheKnownOnes) {
  for (const StudyDescriptor& s : studies()) {
    for (const auto& [experiment, f] : s.summarizers) {
      EXPECT_EQ(&find_summarizer(s.name, experiment), &f) << s.name << " " << experiment;
    }
  }
  try {
    find_summarizer("oneshot", "noise");
    FAIL() << "no summarizer expected";
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(),
                 "no study experiment 'oneshot noise' can merge sweeps (known: dropping arrival, dropping closed-loop, "
                 "dropping hold, ncs table, oneshot kernel, oneshot table1, petc gpi, petc table, sod table, study run, "
                 "study run-dropping, study run-oneshot, study run-petc, study run-sod)");
  }
}

}  // namespace
}  // namespace oneshot::sim
