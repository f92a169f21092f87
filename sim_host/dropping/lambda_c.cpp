/// @file lambda_c.cpp
/// @brief The lambda-c tool (see lambda_c.hpp).
#include "lambda_c.hpp"

#include <cmath>
#include <stdexcept>

namespace oneshot::dropping {
namespace {

template <std::size_t R, std::size_t C>
nlohmann::json matrix_json(const Matrix<double, R, C>& m) {
  nlohmann::json j = nlohmann::json::array();
  for (std::size_t i = 0; i < R; ++i) {
    nlohmann::json row = nlohmann::json::array();
    for (std::size_t c = 0; c < C; ++c) row.push_back(m(i, c));
    j.push_back(row);
  }
  return j;
}

}  // namespace

nlohmann::json mare_point_json(const DroppingPlant& plant, double lambda, const LambdaCOptions& opt) {
  if (!(lambda >= 0 && lambda <= 1)) throw std::invalid_argument("lambda must lie in [0, 1]");
  const MareModel<kN, kP> m = plant.mare();
  Matrix<double, kN, kN> p;
  const MareOutcome o = mare_fixed_point(m, lambda, p, opt.mare);
  nlohmann::json j = {{"lambda", lambda},
                      {"converged", o.converged},
                      {"reason", o.reason},
                      {"iterations", o.iterations}};
  if (o.converged) {
    j["trace_p"] = o.trace;
    // Sinopoli's MARE iterates the prior P(n+1|n) = Φ P̄ Φᵀ + Q of the same fixed point.
    const Matrix<double, kN, kN> prior = mare_prior(m, p);
    j["trace_p_prior_form"] = prior(0, 0) + prior(1, 1) + prior(2, 2);
    j["P"] = matrix_json(p);
    j["K"] = matrix_json(mare_gain(m, p));
  } else {
    j["trace_p"] = nullptr;
    j["trace_p_last_iterate"] = std::isfinite(o.trace) ? nlohmann::json(o.trace) : nlohmann::json(nullptr);
  }
  const Certificate c = certify(m, lambda, opt.certificate_eps_rel, opt.mare);
  j["certificate"] = {{"verdict", c.certified ? "certified" : "refused"},
                      {"reason", c.reason},
                      {"epsilon", c.epsilon},
                      {"min_pivot", std::isfinite(c.min_pivot) ? nlohmann::json(c.min_pivot) : nlohmann::json(nullptr)},
                      {"lmi_size", c.dimension}};
  return j;
}

nlohmann::json lambda_c_report(const DroppingPlant& plant, const LambdaCOptions& opt) {
  if (!(opt.bracket_width > 0 && opt.bracket_width < 1)) throw std::invalid_argument("--width must lie in (0, 1)");
  const MareModel<kN, kP> m = plant.mare();
  const LambdaCBracket b = lambda_c_bisection(m, plant.lambda_sys, opt.bracket_width, opt.mare);
  nlohmann::json j;
  j["plant"] = plant.plant.name;
  j["rho"] = plant.rho;
  j["lambda_sys"] = plant.lambda_sys;
  if (b.hi_converges) {
    j["lambda_c_bracket"] = {b.lo, b.hi};
    j["lambda_c_bracket_width"] = b.hi - b.lo;
  } else {
    j["lambda_c_bracket"] = nullptr;
    j["lambda_c_note"] = "the MARE diverges even at lambda = 1: no bracket";
  }
  j["bisection"] = {{"evaluations", b.evaluations}, {"mare_iterations", b.total_iterations}};
  j["settings"] = {{"tolerance", opt.mare.tolerance},
                   {"divergence_trace", opt.mare.divergence_trace},
                   {"max_iterations", opt.mare.max_iterations},
                   {"bracket_width", opt.bracket_width},
                   {"certificate_eps_rel", opt.certificate_eps_rel}};
  nlohmann::json pts = nlohmann::json::array();
  for (double l : opt.lambdas) pts.push_back(mare_point_json(plant, l, opt));
  j["points"] = pts;
  // Certificates just either side of the bracket: the LMI route agrees with the bisection
  // when it certifies at hi and refuses at lo.
  if (b.hi_converges) {
    j["certificate_at_bracket"] = {
        {"lo", mare_point_json(plant, b.lo, opt).at("certificate")},
        {"hi", mare_point_json(plant, b.hi, opt).at("certificate")}};
  }
  return j;
}

}  // namespace oneshot::dropping
