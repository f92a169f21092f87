/// @file statistics.hpp
/// @brief Sample mean and two-sided 95 % confidence interval (Student t).
#pragma once

#include <cmath>
#include <cstddef>
#include <vector>

#include <nlohmann/json.hpp>

namespace oneshot::util {

/// Mean and the half-width of its 95 % confidence interval.
struct Summary {
  double mean = 0;   ///< Sample mean.
  double sd = 0;     ///< Sample standard deviation (n − 1).
  double ci95 = 0;   ///< t_{0.975, n−1} · sd / √n (0 for n < 2).
  std::size_t n = 0; ///< Sample size.
};

/// t quantile t_{0.975, dof} (exact table to 30 dof, then the Cornish–Fisher series).
double student_t975(std::size_t dof);

/// Summary of `samples`.
Summary summarize(const std::vector<double>& samples);

/// {"mean": s.mean, "ci95": s.ci95}: how the study outputs give a mean with its interval (null
/// where not finite: a diverged run is shown, never hidden, and the JSON stays valid).
inline nlohmann::json mean_ci_json(const Summary& s) {
  const auto num = [](double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); };
  return {{"mean", num(s.mean)}, {"ci95", num(s.ci95)}};
}

}  // namespace oneshot::util
