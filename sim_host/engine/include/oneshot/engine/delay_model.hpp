/// @file delay_model.hpp
/// @brief Per-link delay models: constant, uniform, Poisson in whole periods, a recorded
///        trace, and heavy-tailed lognormal and Pareto.
///
/// Each draw consumes a fixed number of uniforms from the link's delay stream (constant:
/// 0; uniform, Poisson: 1; lognormal: normals of the polar method; Pareto: 1; trace: 0),
/// and the models below (all delays are integer ns, drawn in double and rounded):
///     constant          d
///     uniform           U{min, …, max}                       (integer ns, inclusive; with a
///                       resolution r: min + r·U{0, …, ⌊(max − min)/r⌋}, e.g. whole µs)
///     poisson_periods   offset + K·T,  K ~ Poisson(mean)       (the dropping brief: D whole periods)
///     trace             trace[n mod size] for the n-th message  (recorded delays, cycled)
///     lognormal         shift + median·exp(σ Z),  Z ~ N(0, 1)
///     pareto            shift + scale·U^(−1/α),  U ~ U(0, 1]    (P[X > x] = (scale/x)^α)
/// Heavy-tailed draws (lognormal, Pareto) above `cap` (default one hour) are clamped to it and
/// counted by the link; with sane parameters that never happens, and the count says so.
/// Poisson draws are not capped.
#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "oneshot/engine/random_stream.hpp"
#include "oneshot/engine/sim_time.hpp"

namespace oneshot::engine {

/// A link's delay distribution.
struct DelayModel {
  /// Model kind.
  enum class Kind : std::uint8_t { kConstant, kUniform, kPoissonPeriods, kTrace, kLognormal, kPareto };
  Kind kind = Kind::kConstant;   ///< Model.
  Duration constant{0};          ///< Constant: the delay.
  Duration min{0};               ///< Uniform: smallest delay.
  Duration max{0};               ///< Uniform: largest delay.
  Duration resolution{1};        ///< Uniform: delays are min + j·resolution (1 ns: every integer ns).
  double mean_periods = 0;       ///< Poisson: mean number of whole periods D.
  Duration period{0};            ///< Poisson: the period T.
  Duration shift{0};             ///< Poisson, lognormal, Pareto: added offset.
  double median_ns = 0;          ///< Lognormal: median of the random part.
  double sigma = 0;              ///< Lognormal: σ of its logarithm.
  double scale_ns = 0;           ///< Pareto: scale x_m.
  double alpha = 0;              ///< Pareto: shape α.
  Duration cap{3'600'000'000'000};  ///< Lognormal, Pareto: largest delay (draws above are clamped; Poisson is not capped).
  std::vector<Duration> trace;   ///< Trace: recorded delays, used in order and cycled.
  std::string trace_path;        ///< Trace: the file they came from.

  /// Delay of the `index`-th message (draws from `rng`); `clamped` is set when the cap bit.
  Duration draw(RandomStream& rng, std::uint64_t index, bool& clamped) const;
  /// Smallest delay the model can produce.
  Duration lower_bound() const;
  /// Largest delay the model can produce (constant, uniform, trace); nullopt for the
  /// unbounded models: Poisson (no bound at all: draw() applies no cap to it), lognormal and
  /// Pareto (only their `cap` bounds the draws).
  std::optional<Duration> upper_bound() const;
  /// Mean delay in ns of the draws (exact for every model; a heavy tail's draw clamped at its
  /// cap, so finite for every Pareto α).
  double mean_ns() const;
  /// One-line description.
  std::string describe() const;
};

/// Parses {"model": "constant"|"uniform"|"poisson_periods"|"trace"|"lognormal"|"pareto", …}
/// (see docs/engine.md); std::invalid_argument naming `field` and the key. Trace files are
/// read relative to `base_dir`.
DelayModel parse_delay_model(const nlohmann::json& j, const std::string& field, const std::string& base_dir);

/// Parses the text of a delay trace: header "delay_us", then one non-negative integer per
/// line ('#' comments and blank lines skipped); `source` names it in errors.
std::vector<Duration> parse_delay_trace(const std::string& text, const std::string& source);

}  // namespace oneshot::engine
