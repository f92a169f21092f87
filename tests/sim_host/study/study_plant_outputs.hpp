/// @file study_plant_outputs.hpp
/// @brief What the inline- and discrete-plant tests compare: a sweep's outputs without the
///        keys that only say where the plant came from.
#pragma once

#include <cstdint>
#include <string>

#include <nlohmann/json.hpp>

#include "study_ncs_runner.hpp"
#include "study_ncs_sweep.hpp"
#include "support/temp_files.hpp"

namespace oneshot::study::test_support {

/// The plant file `name` of lut_gen/plants written inline: the same keys, noise and cost flat.
inline nlohmann::json inline_plant_of(const char* name) {
  const nlohmann::json p =
      nlohmann::json::parse(test::read_file(std::string(ONESHOT_STUDY_EXAMPLES_DIR) + "/../../../lut_gen/plants/" + name));
  nlohmann::json c;
  for (const char* k : {"name", "states", "inputs", "outputs", "A", "B", "C", "period_us", "tracked_outputs", "board"}) c[k] = p.at(k);
  c["Q1c"] = p.at("cost").at("Q1c");
  c["Q2c"] = p.at("cost").at("Q2c");
  c["Q_c"] = p.at("noise").at("process_intensity");
  c["measurement_covariance"] = p.at("noise").at("measurement_covariance");
  return {{"continuous", c}};
}

/// `j` without its "plant_source" keys (where the plant came from: the only difference).
inline nlohmann::json without_plant_source(nlohmann::json j) {
  if (j.is_object()) {
    j.erase("plant_source");
    for (auto& [k, v] : j.items()) v = without_plant_source(v);
  } else if (j.is_array()) {
    for (auto& v : j) v = without_plant_source(v);
  }
  return j;
}

/// The sweep's outputs of `s` (first seed `first`, `seeds` seeds) without plant_source.
inline std::string outputs_of(NcsStudy s, std::uint64_t first, std::size_t seeds, const char* dir) {
  s.first_seed = first;
  for (NcsStudy& l : s.loops) l.first_seed = first;
  const engine::SweepResults r = run_ncs_sweep(s, seeds, 2, engine::Shard{});
  return without_plant_source(run_outputs(r, test::fresh_dir("oneshot_study_plant", dir), false)).dump();
}

}  // namespace oneshot::study::test_support
