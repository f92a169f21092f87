/// @file goodness_of_fit.hpp
/// @brief Distribution tests for the random models: one-sample Kolmogorov–Smirnov and
///        Pearson's χ², with their critical values at a stated significance level.
#pragma once

#include <algorithm>
#include <cmath>
#include <functional>
#include <vector>

namespace oneshot::test {

/// Two-sided significance level of every distribution test (a correct model fails 1 in 1000).
inline constexpr double kAlpha = 0.001;
/// Standard normal quantile z_{1 − α/2} for α = 0.001.
inline constexpr double kZ = 3.2905267314919255;

/// Standard normal cdf.
inline double normal_cdf(double x) { return 0.5 * std::erfc(-x / std::sqrt(2.0)); }

/// Kolmogorov–Smirnov statistic D_n = sup |F_n(x) − F(x)| of `samples` against `cdf`.
inline double ks_statistic(std::vector<double> samples, const std::function<double(double)>& cdf) {
  std::sort(samples.begin(), samples.end());
  const double n = static_cast<double>(samples.size());
  double d = 0;
  for (std::size_t i = 0; i < samples.size(); ++i) {
    const double f = cdf(samples[i]);
    d = std::max({d, f - static_cast<double>(i) / n, static_cast<double>(i + 1) / n - f});
  }
  return d;
}

/// Asymptotic KS critical value at α: √(−ln(α/2)/2)/√n (1.9495/√n at α = 0.001).
inline double ks_critical(std::size_t n) { return std::sqrt(-std::log(kAlpha / 2) / 2) / std::sqrt(static_cast<double>(n)); }

/// Pearson's χ² of observed counts against expected counts.
inline double chi_square(const std::vector<double>& observed, const std::vector<double>& expected) {
  double x = 0;
  for (std::size_t i = 0; i < observed.size(); ++i) x += (observed[i] - expected[i]) * (observed[i] - expected[i]) / expected[i];
  return x;
}

/// χ² quantile at 1 − α with `dof` degrees of freedom (Wilson–Hilferty; within 1 % of
/// tables for dof ≥ 3 at α = 0.001, on the conservative side).
inline double chi_square_critical(std::size_t dof) {
  const double k = static_cast<double>(dof);
  const double z = 3.090232306167813;  // z_{0.999}
  const double c = 1 - 2 / (9 * k) + z * std::sqrt(2 / (9 * k));
  return k * c * c * c;
}

}  // namespace oneshot::test
