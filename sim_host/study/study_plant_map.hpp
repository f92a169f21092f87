/// @file study_plant_map.hpp
/// @brief The plant of a study file with "study": "ncs" mapped onto the ncs loop: a plant file
///        (its path resolved against the study file's folder) or the same plant written inline
///        (plant.continuous with the plant file's design keys), or a discrete plant (plant.discrete
///        with the design keys, or a plant file of form discrete with Q1c/Q2c and a board) run as
///        its exact continuous equivalent (design::zoh_inverse).
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
/// "plant.file"), an inline continuous or discrete plant of a shape the loop runs
/// (ncs::kNcsShapesText) with its design keys (refusals naming the key under "plant.continuous" or
/// "plant.discrete"): engine::InputError.
NcsPlant map_ncs_plant(const engine::StudyFile& file);

}  // namespace oneshot::study
