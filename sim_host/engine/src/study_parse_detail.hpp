/// @file study_parse_detail.hpp
/// @brief Internal: the plant section of a study file (study_plant.cpp).
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "oneshot/engine/study_file.hpp"

namespace oneshot::engine::detail {

/// Parses the "plant" object at field `f`: a file, continuous or discrete matrices
/// (shapes consistent, covariances and weights symmetric positive semidefinite, dimensions
/// within the core's limits).
PlantSpec parse_plant(const nlohmann::json& j, const std::string& f);

}  // namespace oneshot::engine::detail
