/// @file controller_design.hpp
/// @brief The constants a control job needs, produced by the host design step.
#pragma once

#include <cstddef>
#include <cstdint>

#include "oneshot/matrix.hpp"

namespace oneshot {

/// How the process noise enters each prediction.
enum class NoiseModel : std::uint8_t {
  kConstant,  ///< The original design: the constant per-step Q added at every prediction.
  kExact,     ///< Q_d(τ) of the actual interval (Van Loan), from the discretizer.
};

/// Actuator range and resolution: u = u_min + code·volts_per_step, code ∈ [0, steps].
template <typename Fmt, std::size_t M>
struct ActuatorModel {
  Vector<typename Fmt::Input, M> u_min;            ///< Input at code 0 (V).
  Vector<typename Fmt::CodeStep, M> volts_per_step;   ///< (u_max − u_min)/steps (V).
  Vector<typename Fmt::InverseInput, M> steps_per_volt;  ///< steps/(u_max − u_min) (1/V).
  std::int32_t steps;                              ///< Resolution steps (e.g. PWM period ticks).
};

/// Sensor conversion (mid-riser ADC): y = y_offset + code·volts_per_code, where
/// y_offset = v_min + LSB/2 puts each code at the centre of its quantisation bin.
template <typename Fmt, std::size_t P>
struct SensorModel {
  Vector<typename Fmt::State, P> y_offset;         ///< Value of code 0 (V).
  Vector<typename Fmt::CodeStep, P> volts_per_code;   ///< One LSB (V).
};

/// Design results for an n-state, m-input, p-output plant (convention u = −L x).
template <typename Fmt, std::size_t N, std::size_t M, std::size_t P>
struct ControllerDesign {
  using Format = Fmt;                          ///< Number formats.
  static constexpr std::size_t kStates = N;    ///< n.
  static constexpr std::size_t kInputs = M;    ///< m.
  static constexpr std::size_t kOutputs = P;   ///< p.
  std::int32_t period_us;                                ///< Control period h (µs).
  Matrix<typename Fmt::Transition, P, N> c;              ///< Output matrix C.
  Matrix<typename Fmt::FeedbackGain, M, N> l;            ///< LQR gain L.
  Matrix<typename Fmt::FeedbackGain, N, P> nx;           ///< x_ref = N_x r.
  Matrix<typename Fmt::FeedbackGain, M, P> nu;           ///< u_ref = N_u r.
  Matrix<typename Fmt::Covariance, N, N> q_constant;     ///< Per-step Q (original design).
  Matrix<typename Fmt::Covariance, P, P> r;              ///< Measurement covariance R.
  Matrix<typename Fmt::Covariance, N, N> p0;             ///< Initial covariance.
  Matrix<typename Fmt::Transition, N, N> phi_h;          ///< Φ(h).
  Matrix<typename Fmt::InputGain, N, M> gamma_h;         ///< Γ(h).
  Matrix<typename Fmt::Covariance, N, N> qd_h;           ///< Q_d(h).
  Matrix<typename Fmt::KalmanGain, N, P> deadbeat_gain;  ///< Current deadbeat observer gain.
  ActuatorModel<Fmt, M> actuator;                        ///< Input range and resolution.
  SensorModel<Fmt, P> sensor;                            ///< ADC code to volts.
};

/// The dimensions and vectors of a plant with the patterns of Structure in format Fmt: the
/// public types of the controller and of every estimator it drives.
template <typename Fmt, typename Structure>
struct StructureTypes {
  static constexpr std::size_t kN = Structure::kStates;   ///< n.
  static constexpr std::size_t kM = Structure::kInputs;   ///< m.
  static constexpr std::size_t kP = Structure::kOutputs;  ///< p.
  using Design = ControllerDesign<Fmt, kN, kM, kP>;       ///< Gains, noise and model at h.
  using StateVec = Vector<typename Fmt::State, kN>;       ///< x̂.
  using OutputVec = Vector<typename Fmt::State, kP>;      ///< y.
  using InputVec = Vector<typename Fmt::Input, kM>;       ///< u.
};

}  // namespace oneshot
