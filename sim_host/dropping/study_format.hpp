/// @file study_format.hpp
/// @brief Number formatting and heavy-tail summaries for the dropping study's tables.
#pragma once

#include <cmath>
#include <string>

#include <nlohmann/json.hpp>

#include "oneshot/engine/quantiles.hpp"
#include "oneshot/util/number_text.hpp"

namespace oneshot::dropping {

/// %.4g (shortest readable form); "nan"/"inf" spelled out.
inline std::string fmt_g(double v) { return util::format_g(v, 4); }

/// Fixed with `digits` decimals.
inline std::string fmt_f(double v, int digits) { return util::format_f(v, digits); }

/// A number for JSON (non-finite → null).
inline nlohmann::json num(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); }

/// {"median", "p10", "p90", "mean", "ci95", "n", "nan_count"}.
inline nlohmann::json tail_json(const engine::TailSummary& t) {
  return {{"median", num(t.median)}, {"p10", num(t.p10)},     {"p90", num(t.p90)},         {"mean", num(t.mean.mean)},
          {"ci95", num(t.mean.ci95)}, {"n", t.mean.n}, {"nan_count", t.nan_count}};
}

/// "median [p10, p90]".
inline std::string band_md(const engine::TailSummary& t) {
  if (std::isnan(t.median)) return "—";
  return fmt_g(t.median) + " [" + fmt_g(t.p10) + ", " + fmt_g(t.p90) + "]";
}

/// "mean ± ci95".
inline std::string mean_md(const engine::TailSummary& t) {
  if (t.mean.n == 0) return "—";
  if (!std::isfinite(t.mean.mean)) return "overflow (not finite)";
  return fmt_g(t.mean.mean) + " ± " + fmt_g(t.mean.ci95);
}

}  // namespace oneshot::dropping
