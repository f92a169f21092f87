/// @file fixed_size.hpp
/// @brief Conversions between run-time sized data and the core's fixed-size types (host).
#pragma once

#include <cstddef>
#include <stdexcept>
#include <vector>

#include "oneshot/controller_design.hpp"
#include "oneshot/design/controller_synthesis.hpp"
#include "oneshot/design/dense_matrix.hpp"
#include "oneshot/generic_discretizer.hpp"
#include "oneshot/number_format.hpp"

namespace oneshot::design {

/// DenseMatrix → Matrix<S, R, C> (shape checked).
template <typename S, std::size_t R, std::size_t C>
Matrix<S, R, C> to_fixed(const DenseMatrix& d) {
  if (d.rows != R || d.cols != C) throw std::logic_error("to_fixed: shape mismatch");
  Matrix<S, R, C> m;
  for (std::size_t k = 0; k < R * C; ++k) m[k] = ScalarTraits<S>::from_double(d.values[k]);
  return m;
}

/// std::vector → Vector<S, R> (length checked).
template <typename S, std::size_t R>
Vector<S, R> to_fixed(const std::vector<double>& v) {
  if (v.size() != R) throw std::logic_error("to_fixed: length mismatch");
  Vector<S, R> m;
  for (std::size_t k = 0; k < R; ++k) m[k] = ScalarTraits<S>::from_double(v[k]);
  return m;
}

/// Matrix<double, R, C> → DenseMatrix.
template <std::size_t R, std::size_t C>
DenseMatrix to_dense(const Matrix<double, R, C>& m) {
  DenseMatrix d = DenseMatrix::zeros(R, C);
  for (std::size_t k = 0; k < R * C; ++k) d.values[k] = m[k];
  return d;
}

/// The continuous model in per-microsecond units for the generic routine.
template <typename S, std::size_t N, std::size_t M>
ContinuousModelPerUs<S, N, M> continuous_model_per_us(const PlantDescription& plant, const DesignResult& design) {
  if (!plant.continuous()) {
    throw DesignError(plant.source + ": the generic discretizer needs a continuous plant (A, B); this one is " +
                      to_string(plant.form));
  }
  ContinuousModelPerUs<S, N, M> model;
  model.a_per_us = to_fixed<S, N, N>(plant.a) * ScalarTraits<S>::from_double(1e-6);
  model.b_per_us = to_fixed<S, N, M>(plant.b) * ScalarTraits<S>::from_double(1e-6);
  model.qc_per_us = to_fixed<S, N, N>(design.qc) * ScalarTraits<S>::from_double(1e-6);
  return model;
}

/// The design in the core's form for a floating scalar S.
template <typename S, std::size_t N, std::size_t M, std::size_t P>
ControllerDesign<UniformFormat<S>, N, M, P> controller_design(const PlantDescription& plant,
                                                              const DesignResult& d) {
  if (!d.lqr_available) throw DesignError(plant.source + ": no LQR gain: " + d.lqr_unavailable_reason);
  if (!plant.has_board) throw DesignError(plant.source + ": the controller's converter models need a PWM 'board'");
  ControllerDesign<UniformFormat<S>, N, M, P> c{};
  c.period_us = plant.period_us;
  c.c = to_fixed<S, P, N>(plant.c);
  c.l = to_fixed<S, M, N>(d.l);
  c.nx = to_fixed<S, N, P>(d.nx);
  c.nu = to_fixed<S, M, P>(d.nu);
  c.q_constant = to_fixed<S, N, N>(d.q_constant);
  c.r = to_fixed<S, P, P>(d.r);
  c.p0 = to_fixed<S, N, N>(d.p0);
  c.phi_h = to_fixed<S, N, N>(d.phi_h);
  c.gamma_h = to_fixed<S, N, M>(d.gamma_h);
  c.qd_h = to_fixed<S, N, N>(d.qd_h);
  c.deadbeat_gain = to_fixed<S, N, P>(d.deadbeat_gain);
  c.actuator.u_min = to_fixed<S, M>(d.u_min);
  c.actuator.volts_per_step = to_fixed<S, M>(d.volts_per_step);
  c.actuator.steps_per_volt = to_fixed<S, M>(d.steps_per_volt);
  c.actuator.steps = d.actuator_steps;
  c.sensor.y_offset = to_fixed<S, P>(d.y_offset);
  c.sensor.volts_per_code = to_fixed<S, P>(d.volts_per_code);
  return c;
}

}  // namespace oneshot::design
