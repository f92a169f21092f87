/// @file ncs_nees.hpp
/// @brief One term of a run's NEES (normalized estimation error squared) on the real states of
///        a plant that may run embedded in a larger shape:
///
///     q = e_kᵀ P⁻¹ e_k,   e_k = x − x̂   (the n real states; a padded state's P is 0).
#pragma once

#include <cstddef>

#include "oneshot/engine/psd_math.hpp"
#include "oneshot/matrix.hpp"

namespace oneshot::ncs::loop {

/// q = e_kᵀ P⁻¹ e_k of the estimate `xh` with covariance `p` of the true state `x` on the first
/// `n_real` states; false when P is not positive there.
template <std::size_t N>
bool nees_term(const Vector<double, N>& x, const Vector<double, N>& xh, const Matrix<double, N, N>& p, std::size_t n_real,
               double& q) {
  if constexpr (N >= 2) {
    if (n_real == 2) {  // the closed form (the board's figures as before, to the bit)
      const double e0 = x[0] - xh[0];
      const double e1 = x[1] - xh[1];
      const double det = p(0, 0) * p(1, 1) - p(0, 1) * p(1, 0);
      if (!(det > 0)) return false;
      // eᵀ P⁻¹ e with P⁻¹ = [[p11, −p01], [−p10, p00]] / det
      q = (e0 * e0 * p(1, 1) - e0 * e1 * (p(0, 1) + p(1, 0)) + e1 * e1 * p(0, 0)) / det;
      return true;
    }
  }
  // eᵀ P⁻¹ e = |L⁻¹ e|², P = L Lᵀ (a Cholesky solve), nothing unless P > 0 on the real states
  Matrix<double, N, N> sym;
  for (std::size_t i = 0; i < N; ++i)
    for (std::size_t j = 0; j < N; ++j) sym(i, j) = 0.5 * (p(i, j) + p(j, i));
  const Matrix<double, N, N> l = engine::psd_cholesky<N>(sym);
  Vector<double, N> z;
  q = 0;
  for (std::size_t i = 0; i < N && i < n_real; ++i) {
    if (!(l(i, i) > 0)) return false;
    double v = x[i] - xh[i];
    for (std::size_t j = 0; j < i; ++j) v -= l(i, j) * z[j];
    z[i] = v / l(i, i);
    q += z[i] * z[i];
  }
  return true;
}

}  // namespace oneshot::ncs::loop
