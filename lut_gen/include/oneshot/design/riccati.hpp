/// @file riccati.hpp
/// @brief Discrete algebraic Riccati equation by the structure-preserving doubling
///        algorithm, and a root-location test, on the core's fixed-size matrices (host).
///
/// DARE (control form): X = AᵀXA − AᵀXG(I + XG)⁻¹… written with G = B R⁻¹ Bᵀ, H = Q:
///   X = Aᵀ X (I + G X)⁻¹ A + H.
/// Doubling (Chu, Fan & Lin): with W_k = I + G_k H_k,
///   A_{k+1} = A_k W_k⁻¹ A_k,  G_{k+1} = G_k + A_k W_k⁻¹ G_k A_kᵀ,
///   H_{k+1} = H_k + A_kᵀ H_k W_k⁻¹ A_k,
/// H_k converges quadratically to the stabilising solution.
#pragma once

#include <cmath>
#include <cstddef>

#include "oneshot/linear_solve.hpp"
#include "oneshot/matrix.hpp"
#include "oneshot/status.hpp"

namespace oneshot::design {

/// ‖M‖₁ of a double matrix.
template <std::size_t R, std::size_t C>
double norm1(const Matrix<double, R, C>& m) {
  double best = 0;
  for (std::size_t j = 0; j < C; ++j) {
    double s = 0;
    for (std::size_t i = 0; i < R; ++i) s += std::fabs(m(i, j));
    best = s > best ? s : best;
  }
  return best;
}

/// Stabilising solution X of X = Aᵀ X (I + G X)⁻¹ A + H (G, H symmetric PSD);
/// kNotConverged when the iteration diverges (no stabilising solution) or stalls.
template <std::size_t N>
Status solve_dare(Matrix<double, N, N> a, Matrix<double, N, N> g, Matrix<double, N, N> h,
                  Matrix<double, N, N>& x) {
  const auto eye = Matrix<double, N, N>::identity();
  for (int iteration = 0; iteration < 100; ++iteration) {
    const Matrix<double, N, N> w = eye + g * h;
    Matrix<double, N, N> w_inv_a;
    Matrix<double, N, N> w_inv_g;
    if (solve(w, a, w_inv_a) != Status::kOk) return Status::kSingular;
    if (solve(w, g, w_inv_g) != Status::kOk) return Status::kSingular;
    const Matrix<double, N, N> a_next = a * w_inv_a;
    Matrix<double, N, N> g_next = g + a * w_inv_g * a.transposed();
    Matrix<double, N, N> h_next = h + a.transposed() * h * w_inv_a;
    // Keep exact symmetry against rounding drift.
    for (std::size_t i = 0; i < N; ++i)
      for (std::size_t j = i + 1; j < N; ++j) {
        g_next(i, j) = g_next(j, i) = 0.5 * (g_next(i, j) + g_next(j, i));
        h_next(i, j) = h_next(j, i) = 0.5 * (h_next(i, j) + h_next(j, i));
      }
    for (std::size_t k = 0; k < N * N; ++k)
      if (!std::isfinite(h_next[k]) || !std::isfinite(g_next[k])) return Status::kNotConverged;  // diverges
    const double change = norm1(h_next - h);
    a = a_next;
    g = g_next;
    h = h_next;
    if (change <= 1e-15 * norm1(h)) {
      x = h;
      return Status::kOk;
    }
  }
  return Status::kNotConverged;
}

/// Coefficients c_0 … c_N of det(zI − M) (c_N = 1), by Faddeev–LeVerrier.
template <std::size_t N>
void characteristic_polynomial(const Matrix<double, N, N>& m, double (&c)[N + 1]) {
  c[N] = 1.0;
  Matrix<double, N, N> mk;  // M_0 = 0
  const auto eye = Matrix<double, N, N>::identity();
  for (std::size_t k = 1; k <= N; ++k) {
    mk = m * mk + eye * c[N - k + 1];
    const Matrix<double, N, N> mm = m * mk;
    double trace = 0;
    for (std::size_t i = 0; i < N; ++i) trace += mm(i, i);
    c[N - k] = -trace / static_cast<double>(k);
  }
}

/// True when every root of Σ c_i z^i (c_N ≠ 0) lies strictly inside the circle |z| < radius,
/// by the Schur–Cohn step-down recursion on the scaled polynomial.
template <std::size_t N>
bool roots_inside(const double (&c)[N + 1], double radius) {
  // a_j: coefficient of z^{N−j} of p(radius·z)/c_N, a_0 = 1.
  double a[N + 1];
  for (std::size_t j = 0; j <= N; ++j) a[j] = c[N - j] * std::pow(radius, static_cast<double>(N - j)) / c[N];
  for (std::size_t i = N; i >= 1; --i) {
    const double k = a[i] / a[0];
    if (!(std::fabs(k) < 1.0)) return false;
    double next[N + 1];
    for (std::size_t j = 0; j < i; ++j) next[j] = (a[j] - k * a[i - j]) / (1.0 - k * k);
    for (std::size_t j = 0; j < i; ++j) a[j] = next[j];
  }
  return true;
}

/// Spectral radius of M to ~1e-9 relative, by bisection on roots_inside().
template <std::size_t N>
double spectral_radius(const Matrix<double, N, N>& m) {
  double c[N + 1];
  characteristic_polynomial(m, c);
  double hi = 1.0;
  while (!roots_inside<N>(c, hi)) hi *= 2.0;
  double lo = 0.0;
  for (int it = 0; it < 80 && hi - lo > 1e-12 * hi; ++it) {
    const double mid = 0.5 * (lo + hi);
    if (roots_inside<N>(c, mid)) hi = mid; else lo = mid;
  }
  return hi;
}

}  // namespace oneshot::design
