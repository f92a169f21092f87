/// @file study_one_shot_discretizer.hpp
/// @brief The one-shot loops' discretizer of a study file (`approaches[i].params.discretizer`):
///        the exact one of the design step ("generic", the default), the plant's Φ/Γ/Q_d
///        look-up table built at design time with lut_gen's table builder ("table": exact
///        between grid points, the residual polynomial), or that table at the nearest grid
///        point ("nearest").
///
/// The one-shot loops (OS, OSp, OSK) predict over one period h every time: the sensor samples
/// at kh on its timer and the actuator applies at (k+1)h on its timer, so the filter's
/// interval τ = h has no jitter. The discretizer is therefore evaluated once, at τ = h, at
/// design time: Φ(h), Γ(h), Q_d(h) (Q_d at noise scale 1; the loop scales it by s). The grid
/// rules of a plant file's `table` (h a multiple of the granularity g, range ≥ h) put h on the
/// grid, so "nearest" reads the same entries as "table" there.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "ncs_model.hpp"
#include "oneshot/design/table_builder.hpp"

namespace oneshot::study {

/// Where a one-shot filter's Φ(h), Γ(h), Q_d(h) come from.
enum class OneShotDiscretizer : std::uint8_t {
  kGeneric,  ///< The design step's exact discretization (matrix exponentials): today's loop.
  kTable,    ///< The look-up table, exact between grid points (TableDiscretizer, SubGrid::kExact).
  kNearest,  ///< The look-up table at the nearest grid point (SubGrid::kNearest).
};

/// "generic", "table", "nearest".
const char* name(OneShotDiscretizer d);
/// The discretizer of a name; nullopt for any other.
std::optional<OneShotDiscretizer> one_shot_discretizer_named(const std::string& word);

/// A one-shot approach's discretization, designed from the plant.
struct OneShotDiscretization {
  OneShotDiscretizer kind = OneShotDiscretizer::kGeneric;  ///< Its source.
  /// Φ(h), Γ(h), Q_d(h) of the table (kTable, kNearest); null for kGeneric (the design's).
  std::shared_ptr<const ncs::OneShotTriple> triple;
  /// The table (kTable, kNearest; null for kGeneric), double storage: the loop's format.
  std::shared_ptr<const design::TableData<double>> table;
  std::size_t table_bytes = 0;       ///< Every byte the look-up reads (table_bytes()); 0 for kGeneric.
  std::int32_t granularity_us = 0;   ///< Grid step g.
  std::int32_t range_us = 0;         ///< Range covered without composition.
  std::size_t levels = 0;            ///< Radix levels.
  std::size_t entries = 0;           ///< Stored grid entries.
  std::int32_t tau_us = 0;           ///< τ the filter takes: h (kNearest: h rounded to the grid, = h).
  /// max |X_table(h) − X(h)| / max |X(h)| against the design's exact Φ(h), Γ(h), Q_d(h).
  double phi_rel_error = 0, gamma_rel_error = 0, qd_rel_error = 0;
};

/// Φ(τ), Γ(τ), Q_d(τ) (noise scale 1) from `table` by the rule `kind` (kTable: exact between
/// grid points; kNearest: τ rounded to the grid first, as the filters do), 0 ≤ τ ≤ 4·range
/// (TableDiscretizer's out-of-range policy: composition beyond the range); `tau_us` becomes the τ
/// used. std::invalid_argument for kGeneric or a τ the table clamps.
ncs::OneShotTriple evaluate_one_shot_table(const design::TableData<double>& table, OneShotDiscretizer kind, std::int32_t& tau_us);

/// The discretization `kind` of the one-shot filter on the context's plant: kGeneric needs
/// nothing; kTable and kNearest build the plant's table (in double, the loop's format) with
/// lut_gen's build_table() on the plant's `table` grid and evaluate it at τ = h.
/// engine::InputError naming `field` (the approach's `params.discretizer`) when the plant has no
/// `table` section, naming `plant_field` when the table cannot be built within its max_bytes.
OneShotDiscretization design_one_shot_discretization(const ncs::Context& ctx, OneShotDiscretizer kind,
                                                     const std::string& field, const std::string& plant_field);

/// The discretization as `study check` gives it per one-shot approach: {"kind", "tau_us",
/// "source"}, and for a table "table" {"bytes", "storage", "granularity_us", "range_us",
/// "levels", "entries"} and "relative_error_at_h" {"phi", "gamma", "qd"}.
nlohmann::json discretizer_json(const OneShotDiscretization& d);

/// That JSON in one line of `study check`'s text ("discretizer table at tau = 50000 us: …").
std::string describe_discretizer(const nlohmann::json& d);

}  // namespace oneshot::study
