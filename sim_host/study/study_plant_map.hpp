/// @file study_plant_map.hpp
/// @brief The plant of a study file with "study": "ncs" mapped onto the ncs loop: a plant file
///        (its path resolved against the study file's folder) or the same plant written inline
///        (plant.continuous with the plant file's design keys); a discrete plant is refused.
#pragma once

#include <memory>
#include <string>

namespace oneshot::engine {
struct StudyFile;
}  // namespace oneshot::engine

namespace oneshot::ncs {
class Context;
}  // namespace oneshot::ncs

namespace oneshot::study {

/// Why a discrete inline plant (plant.discrete) does not run: one line.
inline constexpr const char* kDiscretePlantRefusal =
    "the ncs loop integrates the continuous model between the delays, which fall between samples; a discrete "
    "plant would run only with every delay 0 or a whole number of periods, which the loop does not model: give "
    "plant.continuous (or a plant file)";

/// The plant file a study file names, relative paths taken from the study file's folder.
std::string plant_file_path(const engine::StudyFile& file);

/// A study file's plant resolved onto the ncs loop.
struct NcsPlant {
  std::shared_ptr<const ncs::Context> ctx;  ///< Plant and design.
  std::string plant_path;                   ///< The plant file (resolved; "" inline).
  /// The field holding the plant's measurement covariance ("plant.file", or
  /// "plant.continuous.measurement_covariance" inline): where a refusal of R is named.
  std::string covariance_field;
};

/// The plant of `file` on the ncs loop: a plant file loaded (refusals of its content named
/// "plant.file"), an inline continuous plant of the loop's shape (n = 2, m = 1, p = 2, C = I)
/// with its design keys (refusals naming the key under "plant.continuous"), a discrete plant
/// refused ("plant.discrete", kDiscretePlantRefusal): engine::InputError.
NcsPlant map_ncs_plant(const engine::StudyFile& file);

}  // namespace oneshot::study
