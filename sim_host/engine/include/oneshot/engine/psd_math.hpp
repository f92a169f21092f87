/// @file psd_math.hpp
/// @brief Small dense routines on symmetric positive semidefinite matrices (host engine).
///
/// Covariances of process noise over an interval may be singular (noise on some states
/// only, or an interval of zero length), so the factorizations here accept zero pivots:
/// a Cholesky factor L with L Lᵀ = Q whose columns vanish where Q has no variance, and a
/// pseudo-inverse from the symmetric eigen-decomposition (cyclic Jacobi) with eigenvalues
/// below a relative threshold treated as zero.
#pragma once

#include <cmath>
#include <cstddef>

#include "oneshot/matrix.hpp"

namespace oneshot::engine {

/// Lower-triangular L with L Lᵀ = Q for a symmetric PSD Q (a non-positive pivot gives a
/// zero column).
template <std::size_t N>
Matrix<double, N, N> psd_cholesky(const Matrix<double, N, N>& q) {
  Matrix<double, N, N> l;
  for (std::size_t j = 0; j < N; ++j) {
    double d = q(j, j);
    for (std::size_t k = 0; k < j; ++k) d -= l(j, k) * l(j, k);
    l(j, j) = d > 0 ? std::sqrt(d) : 0;
    for (std::size_t i = j + 1; i < N; ++i) {
      double s = q(i, j);
      for (std::size_t k = 0; k < j; ++k) s -= l(i, k) * l(j, k);
      l(i, j) = l(j, j) > 0 ? s / l(j, j) : 0;
    }
  }
  return l;
}

/// Eigen-decomposition Q = V diag(λ) Vᵀ of a symmetric matrix by cyclic Jacobi rotations
/// (converged to rounding; at most 64 sweeps).
template <std::size_t N>
void symmetric_eigen(Matrix<double, N, N> a, Matrix<double, N, N>& v, Vector<double, N>& lambda) {
  v = Matrix<double, N, N>::identity();
  for (int sweep = 0; sweep < 64; ++sweep) {
    double off = 0;
    double diag = 0;
    for (std::size_t i = 0; i < N; ++i) {
      diag += a(i, i) * a(i, i);
      for (std::size_t j = i + 1; j < N; ++j) off += a(i, j) * a(i, j);
    }
    if (off <= 1e-32 * diag || off == 0) break;
    for (std::size_t p = 0; p < N; ++p)
      for (std::size_t q = p + 1; q < N; ++q) {
        if (a(p, q) == 0) continue;
        // Rotation angle zeroing a(p, q): tan 2θ = 2 a_pq / (a_qq − a_pp).
        const double theta = (a(q, q) - a(p, p)) / (2 * a(p, q));
        const double t = (theta >= 0 ? 1.0 : -1.0) / (std::fabs(theta) + std::sqrt(theta * theta + 1));
        const double c = 1 / std::sqrt(t * t + 1);
        const double s = t * c;
        for (std::size_t k = 0; k < N; ++k) {
          const double akp = a(k, p);
          const double akq = a(k, q);
          a(k, p) = c * akp - s * akq;
          a(k, q) = s * akp + c * akq;
        }
        for (std::size_t k = 0; k < N; ++k) {
          const double apk = a(p, k);
          const double aqk = a(q, k);
          a(p, k) = c * apk - s * aqk;
          a(q, k) = s * apk + c * aqk;
        }
        for (std::size_t k = 0; k < N; ++k) {
          const double vkp = v(k, p);
          const double vkq = v(k, q);
          v(k, p) = c * vkp - s * vkq;
          v(k, q) = s * vkp + c * vkq;
        }
      }
  }
  for (std::size_t i = 0; i < N; ++i) lambda[i] = a(i, i);
}

/// Moore–Penrose pseudo-inverse of a symmetric PSD matrix: eigenvalues below
/// 1e-12 · max eigenvalue count as zero.
template <std::size_t N>
Matrix<double, N, N> psd_pseudo_inverse(const Matrix<double, N, N>& q) {
  Matrix<double, N, N> v;
  Vector<double, N> lambda;
  symmetric_eigen(q, v, lambda);
  double top = 0;
  for (std::size_t i = 0; i < N; ++i) top = std::fmax(top, lambda[i]);
  Matrix<double, N, N> out;
  if (top <= 0) return out;
  for (std::size_t k = 0; k < N; ++k) {
    if (lambda[k] <= 1e-12 * top) continue;
    const double inv = 1 / lambda[k];
    for (std::size_t i = 0; i < N; ++i)
      for (std::size_t j = 0; j < N; ++j) out(i, j) += v(i, k) * inv * v(j, k);
  }
  return out;
}

}  // namespace oneshot::engine
