/// @file number_format.hpp
/// @brief Number-format policy: the scalar type of each physical quantity.
///
/// The filters are written once against these names. A floating build uses one type
/// for everything (UniformFormat); a fixed-point build gives each quantity its own
/// Q format (fixed_format.hpp, chosen by the design step from the plant's numbers).
#pragma once

namespace oneshot {

/// Every quantity in the same scalar S (float or double).
template <typename S>
struct UniformFormat {
  using Transition = S;    ///< Φ entries (dimensionless).
  using InputGain = S;     ///< Γ entries (state unit per input unit).
  using Covariance = S;    ///< P, Q, Q_d, R, innovation variance (V²).
  using InverseCovariance = S;  ///< 1/S of a scalar innovation variance (1/V²).
  using State = S;         ///< x, y, set-points (V).
  using Input = S;         ///< u (V).
  using InverseInput = S;  ///< Actuator steps per volt (1/V).
  using ActuatorSteps = S; ///< A (fractional) number of actuator steps.
  using CodeStep = S;      ///< Volts per converter code (ADC LSB, PWM step).
  using KalmanGain = S;    ///< K (state unit per output unit).
  using FeedbackGain = S;  ///< L and the set-point feed-forward gains.
  using Fraction = S;      ///< Sub-grid residual r ∈ [0, 1) of the table.
  using Compute = S;       ///< Scalar of the generic matrix-exponential routine.
  using ModelA = S;        ///< Entries of A per µs.
  using ModelB = S;        ///< Entries of B per µs.
  using ModelQc = S;       ///< Entries of Q_c·2^kQdScaleShift per µs.
  /// Van Loan runs on Q_c·2^kQdScaleShift (fixed point keeps Q_d's tiny entries in range).
  static constexpr int kQdScaleShift = 0;
};

}  // namespace oneshot
