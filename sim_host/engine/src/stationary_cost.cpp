/// @file stationary_cost.cpp
/// @brief The linear equations of the stationary jump-linear cost (see stationary_cost.hpp).
#include "oneshot/engine/stationary_cost.hpp"

#include <cmath>
#include <string>

#include "oneshot/design/dense_ops.hpp"
#include "oneshot/design/spectrum.hpp"

namespace oneshot::engine {

StationaryCost solve_stationary(std::size_t k, const design::DenseMatrix& ops, const std::vector<double>& w,
                                const std::vector<double>& q, double c, double mean_period_s) {
  const std::size_t n = k * (k + 1) / 2;
  if (ops.rows != n || ops.cols != n || w.size() != n || q.size() != n)
    throw std::invalid_argument("solve_stationary: sizes do not match K = " + std::to_string(k));
  StationaryCost r;
  r.mean_period_s = mean_period_s;
  r.spectral_radius = design::spectral_radius(ops);
  if (!(r.spectral_radius < 1))
    throw std::domain_error("stationary cost: not mean-square stable (spectral radius of the covariance map " +
                            std::to_string(r.spectral_radius) + " >= 1): the expected cost grows without bound");
  // (I − 𝒜) vech Σ = w.
  design::DenseMatrix a = design::identity(n) - ops;
  design::DenseMatrix b = design::DenseMatrix::zeros(n, 1);
  for (std::size_t i = 0; i < n; ++i) b(i, 0) = w[i];
  const design::SolveResult s = design::solve(a, b);
  if (!s.ok) throw std::domain_error("stationary cost: I − covariance map singular (rcond " + std::to_string(s.rcond) + ")");
  r.sigma = design::DenseMatrix::zeros(k, k);
  double cost = c;
  std::size_t idx = 0;
  for (std::size_t i = 0; i < k; ++i)
    for (std::size_t j = i; j < k; ++j, ++idx) {
      r.sigma(i, j) = s.x(idx, 0);
      r.sigma(j, i) = s.x(idx, 0);
      cost += q[idx] * s.x(idx, 0);
    }
  // Residual of the fixed point, relative to the largest entry of Σ.
  double worst = 0;
  double scale = 0;
  for (std::size_t i = 0; i < n; ++i) {
    double v = w[i];
    for (std::size_t j = 0; j < n; ++j) v += ops(i, j) * s.x(j, 0);
    worst = std::fmax(worst, std::fabs(v - s.x(i, 0)));
    scale = std::fmax(scale, std::fabs(s.x(i, 0)));
  }
  r.residual = scale > 0 ? worst / scale : worst;
  r.cost_per_period = cost;
  r.cost_rate = cost / mean_period_s;
  return r;
}

}  // namespace oneshot::engine
