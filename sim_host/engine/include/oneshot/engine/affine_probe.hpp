/// @file affine_probe.hpp
/// @brief The affine map of a computation that is affine in its inputs (a firmware estimator
///        and control law with the timing fixed), probed on copies: f(w) = J w + b.
///
/// f is evaluated at w0 and at w0 + δ e_j for every input j; column j of J is the difference
/// over δ and b = f(w0) − J w0. Exact up to rounding for an affine f: the analytic modes run
/// the firmware's own code this way rather than a re-derivation of its maps.
#pragma once

#include <cstddef>

#include "oneshot/matrix.hpp"

namespace oneshot::engine {

/// J (O×W) and b of f: ℝ^W → ℝ^O (affine) around w0, with step `delta` (> 0).
template <std::size_t W, std::size_t O, typename F>
void probe_affine(const F& f, const Vector<double, W>& w0, double delta, Matrix<double, O, W>& jac,
                  Vector<double, O>& offset) {
  const Vector<double, O> y0 = f(w0);
  offset = y0;
  for (std::size_t j = 0; j < W; ++j) {
    Vector<double, W> w = w0;
    w[j] += delta;
    const Vector<double, O> y = f(w);
    for (std::size_t i = 0; i < O; ++i) {
      const double col = (y[i] - y0[i]) / delta;
      jac(i, j) = col;
      offset[i] -= col * w0[j];
    }
  }
}

}  // namespace oneshot::engine
