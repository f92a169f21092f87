/// @file study_example.hpp
/// @brief A shipped example study file (sim_host/study/examples/) as the study tests use it:
///        its JSON, the file parsed with the ncs schema, mapped onto the loop after an edit, and
///        the refusal of an edited file checked by the field it names.
#pragma once

#include <gtest/gtest.h>

#include <functional>
#include <string>
#include <utility>

#include <nlohmann/json.hpp>

#include "oneshot/engine/study_file.hpp"
#include "study_check.hpp"
#include "study_ncs_runner.hpp"
#include "support/temp_files.hpp"

namespace oneshot::study::test_support {

/// An edit of the file's JSON before it is parsed.
using Edit = std::function<void(nlohmann::json&)>;

/// The example `file_name` of ONESHOT_STUDY_EXAMPLES_DIR.
class StudyExample {
 public:
  /// The example called `file_name` (e.g. "ncs_can.json").
  explicit StudyExample(const std::string& file_name)
      : path_(std::string(ONESHOT_STUDY_EXAMPLES_DIR) + "/" + file_name) {}

  /// Its path.
  const std::string& path() const { return path_; }

  /// Its JSON, as shipped.
  nlohmann::json json() const { return nlohmann::json::parse(test::read_file(path_)); }

  /// `j` parsed as this file (relative paths from the examples folder).
  engine::StudyFile parse(const nlohmann::json& j) const {
    return engine::parse_study(j.dump(), path_, &ncs_schema(), ONESHOT_STUDY_EXAMPLES_DIR);
  }

  /// The file after `edit`, mapped onto the loop (with the check's bus bounds when it has a
  /// bus), every scenario (of every loop) `duration_s` long.
  NcsStudy study(const Edit& edit, double duration_s) const {
    nlohmann::json j = json();
    edit(j);
    const engine::StudyFile f = parse(j);
    NcsStudy s = map_ncs_study(f);
    for (ncs::Scenario& x : s.scenarios) x.duration_s = duration_s;
    for (NcsStudy& loop : s.loops)  // a file with several loops: every loop's scenarios
      for (ncs::Scenario& x : loop.scenarios) x.duration_s = duration_s;
    if (!f.buses.empty()) attach_bus_bounds(s, resolve_study(f));
    return s;
  }

  /// Parsing (then with `check` the study check) and mapping the file after `edit` is refused
  /// with a message containing `expect`.
  void expect_refused(const Edit& edit, const std::string& expect, bool check = false) const {
    nlohmann::json j = json();
    edit(j);
    try {
      const engine::StudyFile f = parse(j);
      if (check) static_cast<void>(resolve_study(f));
      static_cast<void>(map_ncs_study(f));
      ADD_FAILURE() << "accepted, expected " << expect;
    } catch (const engine::InputError& e) {
      EXPECT_NE(std::string(e.what()).find(expect), std::string::npos) << e.what();
    }
  }

 private:
  std::string path_;
};

}  // namespace oneshot::study::test_support
