/// @file study_sweep_checks.hpp
/// @brief A study file's sweep is the same bytes however it runs: on one or two threads, or as
///        shards written to JSON and merged (what `study run --shard` and `merge` give).
#pragma once

#include <gtest/gtest.h>

#include <cstddef>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "oneshot/engine/sweep.hpp"
#include "study_ncs_sweep.hpp"
#include "support/temp_files.hpp"

namespace oneshot::study::test_support {

/// run_outputs() (no plots, files in `dir`) of `s` over `seeds` seeds run as three shards on
/// one thread, each shard through its JSON text, then merged.
inline nlohmann::json merged_shard_outputs(const NcsStudy& s, std::size_t seeds, const std::string& dir,
                                           bool analytic = false) {
  std::vector<engine::SweepResults> parts;
  for (std::size_t i = 0; i < 3; ++i) {
    const engine::SweepResults p = run_ncs_sweep(s, seeds, 1, engine::Shard{i, 3}, analytic);
    parts.push_back(engine::shard_from_json(nlohmann::json::parse(engine::shard_to_json(p).dump())));
  }
  return run_outputs(engine::merge_shards(parts), dir, false);
}

/// `s` over `seeds` seeds gives the same outputs, byte for byte, on one and two threads and
/// from three merged shards (output folders "one", "two", "merged" of the temporary folder
/// `temp_prefix`), and they hold the key `key`.
inline void expect_same_bytes_on_threads_and_shards(const NcsStudy& s, std::size_t seeds, const std::string& temp_prefix,
                                                    const char* key) {
  const std::string one =
      run_outputs(run_ncs_sweep(s, seeds, 1, engine::Shard{}), test::fresh_dir(temp_prefix, "one"), false).dump();
  const std::string two =
      run_outputs(run_ncs_sweep(s, seeds, 2, engine::Shard{}), test::fresh_dir(temp_prefix, "two"), false).dump();
  EXPECT_EQ(one, two);
  EXPECT_EQ(merged_shard_outputs(s, seeds, test::fresh_dir(temp_prefix, "merged")).dump(), two);
  EXPECT_TRUE(nlohmann::json::parse(two).contains(key)) << key;
}

}  // namespace oneshot::study::test_support
