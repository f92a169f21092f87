/// @file ncs_shape_design.cpp
/// @brief The controller design and the discretizer's model of study ncs's plant for the loop's
///        shape S (ncs_model.hpp): the plant's own when S is its shape, else embedded in S —
///        zero padded, the padded parts inert (A = 0 there, so Φ = I; no input, output, noise or
///        cost; R's padded diagonal on the real R's scale).
#include <cmath>
#include <cstddef>
#include <stdexcept>
#include <vector>

#include "ncs_model.hpp"
#include "oneshot/design/fixed_size.hpp"

namespace oneshot::ncs {

namespace {

/// The R × C matrix holding `d` in its top-left corner, 0 elsewhere but `pad_diagonal` on the
/// diagonal entries past d's (a plant embedded in a larger shape; std::logic_error when d is larger).
template <std::size_t R, std::size_t C>
Matrix<double, R, C> padded(const design::DenseMatrix& d, double pad_diagonal = 0) {
  if (d.rows > R || d.cols > C) throw std::logic_error("ncs: a matrix larger than the loop's shape");
  Matrix<double, R, C> out{};
  for (std::size_t i = 0; i < d.rows; ++i)
    for (std::size_t j = 0; j < d.cols; ++j) out(i, j) = d(i, j);
  for (std::size_t i = d.rows; i < R && i < C; ++i) out(i, i) = pad_diagonal;
  return out;
}

/// The R-vector holding `v` first, `pad` after.
template <std::size_t R>
Vector<double, R> padded(const std::vector<double>& v, double pad) {
  if (v.size() > R) throw std::logic_error("ncs: a vector longer than the loop's shape");
  Vector<double, R> out;
  for (std::size_t i = 0; i < R; ++i) out[i] = i < v.size() ? v[i] : pad;
  return out;
}

}  // namespace

template <typename S>
typename S::Design Context::controller_design_of(double s) const {
  typename S::Design d;
  if (plant_.a.rows == S::n && plant_.b.cols == S::m && plant_.c.rows == S::p) {
    d = design::controller_design<double, S::n, S::m, S::p>(plant_, design_);
  } else {  // embedded: the same checks, then the design zero padded
    if (!design_.lqr_available) throw design::DesignError(plant_.source + ": no LQR gain: " + design_.lqr_unavailable_reason);
    if (!plant_.has_board) throw design::DesignError(plant_.source + ": the controller's converter models need a PWM 'board'");
    d = typename S::Design{};
    d.period_us = plant_.period_us;
    d.c = padded<S::p, S::n>(plant_.c);
    d.l = padded<S::m, S::n>(design_.l);
    d.nx = padded<S::n, S::p>(design_.nx);
    d.nu = padded<S::m, S::p>(design_.nu);
    d.q_constant = padded<S::n, S::n>(design_.q_constant);
    // S = C P Cᵀ + R stays invertible: the padded diagonal on the real R's scale (its largest
    // diagonal entry, 1 when R is 0), so the padded entries never raise the norm the solve's
    // singularity test takes (a pad of 1 beside R ≈ 1e-18 made every correction "singular").
    double r_pad = 0;
    for (std::size_t i = 0; i < design_.r.rows; ++i) r_pad = std::fmax(r_pad, design_.r(i, i));
    d.r = padded<S::p, S::p>(design_.r, r_pad > 0 ? r_pad : 1.0);
    d.p0 = padded<S::n, S::n>(design_.p0);
    d.phi_h = padded<S::n, S::n>(design_.phi_h, 1.0);  // padded A = 0: Φ = I there
    d.gamma_h = padded<S::n, S::m>(design_.gamma_h);
    d.qd_h = padded<S::n, S::n>(design_.qd_h);
    if (design_.deadbeat_gain.rows == plant_.a.rows && design_.deadbeat_gain.cols == plant_.c.rows) {
      d.deadbeat_gain = padded<S::n, S::p>(design_.deadbeat_gain);
    }
    d.actuator.u_min = padded<S::m>(design_.u_min, -1.0);  // a padded input in [−1, 1] (u_max: BasicHarness) holds its 0
    d.actuator.volts_per_step = padded<S::m>(design_.volts_per_step, 1.0);
    d.actuator.steps_per_volt = padded<S::m>(design_.steps_per_volt, 1.0);
    d.actuator.steps = design_.actuator_steps;
    d.sensor.y_offset = padded<S::p>(design_.y_offset, 0.0);
    d.sensor.volts_per_code = padded<S::p>(design_.volts_per_code, 1.0);
  }
  d.q_constant = d.q_constant * s;
  d.r = d.r * s;
  if (identity_output_) {  // brief §3: P⁻ = 10·R (on the real n = p states; 0 on the padded ones)
    const std::size_t n = plant_.a.rows;
    d.p0 = Matrix<double, S::n, S::n>{};
    for (std::size_t i = 0; i < n; ++i)
      for (std::size_t j = 0; j < n; ++j) d.p0(i, j) = d.r(i, j) * 10.0;
  } else {
    d.p0 = d.p0 * s;  // the design step's P0 (initial covariance or Kalman prior, at s = 1)
  }
  return d;
}

template <typename S>
typename S::Disc::Model Context::discretizer_model_of(double s) const {
  typename S::Disc::Model m;
  if (plant_.a.rows == S::n && plant_.b.cols == S::m) {
    m = design::continuous_model_per_us<double, S::n, S::m>(plant_, design_);
  } else {  // embedded: A, B, Q_c zero padded, per µs
    m.a_per_us = padded<S::n, S::n>(plant_.a) * 1e-6;
    m.b_per_us = padded<S::n, S::m>(plant_.b) * 1e-6;
    m.qc_per_us = padded<S::n, S::n>(design_.qc) * 1e-6;
  }
  m.qc_per_us = m.qc_per_us * s;
  return m;
}

#define ONESHOT_NCS_CONTEXT_OF(n, m, p)                                                                      \
  template Shape<n, m, p>::Design Context::controller_design_of<Shape<n, m, p>>(double) const;              \
  template Shape<n, m, p>::Disc::Model Context::discretizer_model_of<Shape<n, m, p>>(double) const;
ONESHOT_NCS_SHAPES(ONESHOT_NCS_CONTEXT_OF)
#undef ONESHOT_NCS_CONTEXT_OF

}  // namespace oneshot::ncs
