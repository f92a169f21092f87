/// @file study_parse_detail.hpp
/// @brief Internal: the plant section of a study file (study_plant.cpp) and the params of its
///        approaches and scenarios (study_params.cpp).
#pragma once

#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "oneshot/engine/study_file.hpp"

namespace oneshot::engine::detail {

/// Parses the "plant" object at field `f`: a file, continuous or discrete matrices
/// (shapes consistent, covariances and weights symmetric positive semidefinite, dimensions
/// within the core's limits).
PlantSpec parse_plant(const nlohmann::json& j, const std::string& f);

/// The "params" object of `j` at field `f`: numbers (finite; with `specs` known, in range, whole
/// when asked, defaults filled in) and, when `words` is given, word parameters into *words (one
/// of their spec's words; any word without `specs`); InputError naming `f.params.<key>`.
std::map<std::string, double> parse_params(const nlohmann::json& j, const std::string& f, const std::vector<ParamSpec>* specs,
                                           std::map<std::string, std::string>* words = nullptr);

}  // namespace oneshot::engine::detail
