/// @file control_law.hpp
/// @brief State feedback with set-point feed-forward, and the actuator's quantisation.
///
///   x_ref = N_x r,  u_ref = N_u r,  u = u_ref − L (x̂ − x_ref)      (convention u = −L x)
/// The actuator realises u with a finite resolution and range:
///   code = clamp(round((u − u_min)·steps_per_volt), 0, steps),  u_applied = u_min + code·volts_per_step
/// and the estimators are told u_applied, the input the plant actually receives.
#pragma once

#include <cstddef>
#include <cstdint>

#include "oneshot/accumulator.hpp"
#include "oneshot/controller_design.hpp"
#include "oneshot/matrix.hpp"
#include "oneshot/structured_ops.hpp"

namespace oneshot {

/// u = N_u r − L (x̂ − N_x r), with the patterns of Structure.
template <typename Fmt, typename Structure, std::size_t N, std::size_t M, std::size_t P>
constexpr Vector<typename Fmt::Input, M> control_law(const ControllerDesign<Fmt, N, M, P>& design,
                                                     const Vector<typename Fmt::State, N>& x,
                                                     const Vector<typename Fmt::State, P>& setpoint) {
  using NxP = typename Structure::StateFeedforwardPattern;
  using NuP = typename Structure::InputFeedforwardPattern;
  using LP = typename Structure::FeedbackPattern;
  Vector<typename Fmt::State, N> error;  // x̂ − N_x r
  for (std::size_t i = 0; i < N; ++i) {
    Accumulator<typename Fmt::State> acc;
    acc.add(x[i]);
    accumulate_row<NxP, RowSign::kSubtract>(acc, design.nx, i, setpoint);
    error[i] = acc.value();
  }
  Vector<typename Fmt::Input, M> u;
  for (std::size_t j = 0; j < M; ++j) {
    Accumulator<typename Fmt::Input> acc;
    accumulate_row<NuP, RowSign::kAdd>(acc, design.nu, j, setpoint);
    accumulate_row<LP, RowSign::kSubtract>(acc, design.l, j, error);
    u[j] = acc.value();
  }
  return u;
}

/// Actuator code of input j for the desired u (saturated to [0, steps]).
template <typename Fmt, std::size_t M>
constexpr std::int32_t quantize_input(const ActuatorModel<Fmt, M>& actuator, std::size_t j,
                                      typename Fmt::Input u) {
  using In = typename Fmt::Input;
  const In offset = u - actuator.u_min[j];
  if (!(ScalarTraits<In>::zero() < offset)) return 0;
  using Steps = typename Fmt::ActuatorSteps;
  const Steps steps = mul<Steps>(offset, actuator.steps_per_volt[j]);
  if (!(steps < ScalarTraits<Steps>::from_int(actuator.steps))) return actuator.steps;
  const std::int32_t code = ScalarTraits<Steps>::round_to_int(steps);
  return code > actuator.steps ? actuator.steps : code;
}

/// offset + code·step: the value of an integer converter code.
template <typename S, typename Step>
constexpr S value_of_code(S offset, Step step, std::int32_t code) {
  Accumulator<S> acc;
  acc.add(offset);
  acc.add_product(count_of<S>(code), step);
  return acc.value();
}

/// The input the actuator realises for `code`.
template <typename Fmt, std::size_t M>
constexpr typename Fmt::Input input_of_code(const ActuatorModel<Fmt, M>& actuator, std::size_t j,
                                            std::int32_t code) {
  return value_of_code(actuator.u_min[j], actuator.volts_per_step[j], code);
}

/// The measured value of ADC `code` on output o.
template <typename Fmt, std::size_t P>
constexpr typename Fmt::State output_of_code(const SensorModel<Fmt, P>& sensor, std::size_t o,
                                             std::int32_t code) {
  return value_of_code(sensor.y_offset[o], sensor.volts_per_code[o], code);
}

}  // namespace oneshot
