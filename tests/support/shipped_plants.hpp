/// @file shipped_plants.hpp
/// @brief The plant files shipped in lut_gen/plants/, for the suites that run over every one.
#pragma once

#include <string>

namespace oneshot::test {

/// The shipped plant files (ONESHOT_PLANTS_DIR), every one of them.
inline constexpr const char* kShippedPlantFiles[] = {"reference_board.json", "networked_board.json",
                                                     "sinopoli_dropping.json", "send_on_delta_oscillator.json",
                                                     "hdd_numre.json"};

/// A plant file's name without its extension: its parameterized test case's name.
inline std::string plant_file_stem(const std::string& file) { return file.substr(0, file.find('.')); }

}  // namespace oneshot::test
