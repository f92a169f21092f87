/// @file lambda_c.hpp
/// @brief `oneshot-sim dropping lambda-c`: λ_sys, the MARE fixed point at given λ, λc by
///        bisection and the LMI certificate at each λ (brief §5), as JSON.
#pragma once

#include <cstddef>
#include <vector>

#include <nlohmann/json.hpp>

#include "dropping_plant.hpp"

namespace oneshot::dropping {

/// Settings of the lambda-c tool.
struct LambdaCOptions {
  std::vector<double> lambdas{1.0, 0.44, 0.364, 0.3};  ///< λ at which P̄ and the certificate are reported.
  double bracket_width = 1e-4;                         ///< Bisection stops when hi − lo ≤ this.
  double certificate_eps_rel = 1e-6;                   ///< ε = this · max|P̄_λ|.
  MareSettings mare;                                   ///< Iteration settings.
};

/// Runs the tool on `plant`: {"lambda_sys", "rho", "lambda_c_bracket": [lo, hi], "points": [...]}.
nlohmann::json lambda_c_report(const DroppingPlant& plant, const LambdaCOptions& opt);

/// The fixed point at one λ as JSON: converged, reason, iterations, trace_p, P, K̄, certificate.
nlohmann::json mare_point_json(const DroppingPlant& plant, double lambda, const LambdaCOptions& opt);

}  // namespace oneshot::dropping
