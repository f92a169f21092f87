/// @file study_fuzz_support.hpp
/// @brief What the study-file harnesses (fuzz_study, fuzz_study_run) share: the folder their
///        inputs are parsed in, and their oracles for refusals and figures.
#pragma once

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <system_error>

#include <nlohmann/json.hpp>

#include "fuzz_oracle.hpp"
#include "oneshot/engine/study_file.hpp"

namespace oneshot::fuzz {

/// The harness's folder: inputs are parsed as files "fuzz.json" there, beside study ncs's plant
/// file "networked_board.json" (copied from `plant_file`) and a delay trace "delays.csv".
/// Made once (on /dev/shm where there is one: writes there are not synced to a disk), removed
/// at exit.
inline const std::string& study_folder(const char* plant_file) {
  static const std::string dir = [plant_file] {
    char shm[] = "/dev/shm/oneshot-fuzz-study-XXXXXX";
    char tmp[] = "/tmp/oneshot-fuzz-study-XXXXXX";
    const char* d = ::mkdtemp(shm);
    if (d == nullptr) d = ::mkdtemp(tmp);
    if (d == nullptr) std::abort();
    const std::string made = d;
    std::ofstream(made + "/delays.csv") << "delay_us\n500\n# a comment\n1500\n\n250\n";
    std::filesystem::copy_file(plant_file, made + "/networked_board.json");
    return made;
  }();
  static const bool removed_at_exit = std::atexit([] {
    std::error_code ec;
    std::filesystem::remove_all(dir, ec);
  }) == 0;
  static_cast<void>(removed_at_exit);
  return dir;
}

/// Every number of `j` finite (null allowed: unbounded figures); `what` names the producer.
inline void require_finite_json(const nlohmann::json& j, const std::string& where, const std::string& what) {
  if (j.is_number()) require(std::isfinite(j.get<double>()), what + ": non-finite figure at " + where);
  if (j.is_structured()) {
    for (const auto& [k, v] : j.items()) require_finite_json(v, where + "." + k, what);
  }
}

/// A refusal of `what` names the field ("field '…'").
inline void require_named(const engine::InputError& e, const std::string& what) {
  require(std::string(e.what()).find("field '") != std::string::npos, what + " refused without naming a field: " + e.what());
}

}  // namespace oneshot::fuzz
