/// @file design_report.hpp
/// @brief The design in JSON and in human form (host).
#pragma once

#include <nlohmann/json.hpp>
#include <ostream>

#include "oneshot/design/controller_synthesis.hpp"
#include "oneshot/design/dense_matrix.hpp"
#include "oneshot/design/plant_description.hpp"

namespace oneshot::design {

/// Row-major nested list (matrices), or a flat list for a single row/column vector.
nlohmann::json matrix_json(const DenseMatrix& m);

/// Flat list of a matrix's entries in row-major order.
nlohmann::json flat_json(const DenseMatrix& m);

/// The design as JSON: Phi_h, Gamma_h (list), L (list, u = −L x), kalman_gain (list),
/// h_s, plus the sampled cost, covariances, feed-forward and stability margins.
nlohmann::json design_json(const PlantDescription& plant, const DesignResult& design);

/// The design as readable text.
void print_design(std::ostream& out, const PlantDescription& plant, const DesignResult& design);

}  // namespace oneshot::design
