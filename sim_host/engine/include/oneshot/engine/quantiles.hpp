/// @file quantiles.hpp
/// @brief Sample quantiles and a heavy-tail summary (median, 10–90 % band, mean with its
///        95 % interval) of a metric over seeds.
///
/// Quantile q of n sorted values x₀ ≤ … ≤ x_{n−1}: linear interpolation at position
/// h = (n − 1) q (Hyndman & Fan's type 7, the common default). NaN values are left out
/// and counted; infinities sort to the ends.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <vector>

#include "oneshot/util/statistics.hpp"

namespace oneshot::engine {

/// Quantile q ∈ [0, 1] of `sorted` (ascending, no NaN); NaN when empty.
inline double sorted_quantile(const std::vector<double>& sorted, double q) {
  if (sorted.empty()) return std::numeric_limits<double>::quiet_NaN();
  const double h = static_cast<double>(sorted.size() - 1) * q;
  const auto lo = static_cast<std::size_t>(std::floor(h));
  const std::size_t hi = std::min(lo + 1, sorted.size() - 1);
  const double f = h - static_cast<double>(lo);
  return f == 0 ? sorted[lo] : sorted[lo] + f * (sorted[hi] - sorted[lo]);
}

/// Median, 10–90 % band and mean with its 95 % interval of a sample (NaNs left out).
struct TailSummary {
  double median = std::numeric_limits<double>::quiet_NaN();       ///< 50 % quantile.
  double p10 = std::numeric_limits<double>::quiet_NaN();          ///< 10 % quantile.
  double p90 = std::numeric_limits<double>::quiet_NaN();          ///< 90 % quantile.
  util::Summary mean;         ///< Mean, sd, 95 % interval (Student t) of the finite values.
  std::size_t nan_count = 0; ///< Values left out (NaN).
};

/// Summary of `values` (any order).
inline TailSummary tail_summary(std::vector<double> values) {
  TailSummary t;
  const auto end = std::remove_if(values.begin(), values.end(), [](double v) { return std::isnan(v); });
  t.nan_count = static_cast<std::size_t>(values.end() - end);
  values.erase(end, values.end());
  std::sort(values.begin(), values.end());
  t.median = sorted_quantile(values, 0.5);
  t.p10 = sorted_quantile(values, 0.1);
  t.p90 = sorted_quantile(values, 0.9);
  t.mean = util::summarize(values);
  return t;
}

}  // namespace oneshot::engine
