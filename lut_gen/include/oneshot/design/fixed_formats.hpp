/// @file fixed_formats.hpp
/// @brief The design step's choice of a Q format for each quantity of the fixed-point job.
///
/// Each quantity gets the largest number of fractional bits that still holds its range
/// with headroom, in the narrowest storage that meets its resolution requirement:
///   state, input        32 bit; range 2× the converter range. 16 bits would do for the
///                       values, but their rounding biases (e.g. −1.65 V in Q2.13) are
///                       integrated by the model like an input disturbance: a double
///                       integrator's estimate drifts by ~2 ADC LSB (fixed_kalman_test)
///   Φ, Γ entries        16 bit; range 1.25× max over [0, 2·max(h, table range)] (complete filter)
///   covariance          32 bit; range 256× max(P0, steady-state P, R, Q_d(2h), Qn); resolution
///                       ≤ 10⁻⁴ of the smallest steady-state variance
///   1/S                 32 bit; range 2/min(R)
///   K, L, N_x, N_u      16 bit; range 2× max(|K∞|, 1) and 2× max |gain|
///   r (sub-grid)        Q0.15
///   generic routine     32 bit; range 2× max(|Φ|, |Γ|); A/B/Q_c per µs in their own formats,
///                       Q_c pre-scaled by 2^k so Van Loan's Q_d block is O(1)
/// A plant whose numbers cannot meet a requirement is refused with the quantity named.
#pragma once

#include <string>
#include <vector>

#include "oneshot/design/controller_synthesis.hpp"
#include "oneshot/design/plant_description.hpp"

namespace oneshot::design {

/// A signed Q format: `bits`-bit storage (16 or 32), value = raw · 2^−frac.
struct QFormat {
  int bits = 16;  ///< Storage width.
  int frac = 0;   ///< Fractional bits.
  /// Largest representable magnitude.
  double max_value() const;
  /// One LSB.
  double resolution() const;
  /// C++ spelling, e.g. ::oneshot::Fixed<std::int16_t, 13>.
  std::string cpp_type() const;
  /// Raw mantissa of v (rounded; DesignError naming `what` when out of range).
  long long raw_of(double v, const std::string& what) const;
};

/// One quantity's format with the range it was chosen for.
struct QuantityFormat {
  std::string name;       ///< Quantity (e.g. "covariance").
  QFormat format;         ///< Chosen format.
  double range = 0;       ///< Largest magnitude it must hold.
  std::string rationale;  ///< Where the range comes from.
};

/// Formats of every quantity of the fixed-point control job.
struct FixedFormats {
  QFormat transition, input_gain, covariance, inverse_covariance, state, input, inverse_input, actuator_steps,
      code_step, kalman_gain, feedback_gain, fraction, compute, model_a, model_b, model_qc;
  int qd_scale_shift = 0;                ///< k of Q_c·2^k in the generic routine.
  std::vector<QuantityFormat> table;     ///< Every choice, for the report and the header.
};

/// Chooses the formats from the plant and its design; DesignError naming the quantity
/// that does not fit.
FixedFormats choose_fixed_formats(const PlantDescription& plant, const DesignResult& design);

/// Largest time the filters evaluate Φ at (the complete filter's a + b ≤ 2·max(h, range)), µs.
std::int32_t fixed_time_span_us(const PlantDescription& plant);

}  // namespace oneshot::design
