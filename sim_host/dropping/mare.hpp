/// @file mare.hpp
/// @brief The modified algebraic Riccati equation of intermittent Kalman filtering, the
///        critical arrival probability and the rescaled LMI certificate (brief §5).
///
///     M = Φ P Φᵀ + Q,   g_λ(P) = M − λ M Cᵀ (C M Cᵀ + R)⁻¹ C M            (MARE, 19)
///     K̄(P) = M Cᵀ (C M Cᵀ + R)⁻¹                                          (18)
///     λ_sys = 1 − 1/ρ(Φ)²  (0 when ρ < 1)                                   (28)
/// The fixed point is iterated from P = 0 with P mirrored every step (the antisymmetric
/// part of the rounding error otherwise grows). λc: bisection on [λ_sys, 1] of "the
/// iteration converges". Certificate at λ: the fixed point p of p = g_λ(p) + εI gives
/// K = K̄(p) with Ω(p, λ, K) = p − εI < p; Ω < p is the Schur-complement LMI
///     Ψ = [[p, F], [Fᵀ, D]] > 0,   F = [√(1−λ)Φp, √λ A Φp, √(1−λ)Q, √λ A Q, √λ K R],
///     D = diag(p, p, Q, Q, R),  A = I − K C                                   (23, in P)
/// which, congruence-scaled by T = diag(Lp⁻¹, Lp⁻¹, Lp⁻¹, L_Q⁻¹, L_Q⁻¹, L_R⁻¹) (Cholesky
/// factors, p = Lp Lpᵀ) to a unit diagonal, is proved positive definite by a Cholesky
/// factorization (−TΨTᵀ < 0 is the paper's negative-definite form). Host only.
#pragma once

#include <cmath>
#include <cstddef>
#include <limits>
#include <string>
#include <vector>

#include "oneshot/matrix.hpp"

namespace oneshot::dropping {

/// The plant seen by the MARE (per step).
template <std::size_t N, std::size_t P>
struct MareModel {
  Matrix<double, N, N> phi;  ///< Φ.
  Matrix<double, N, N> q;    ///< Q.
  Matrix<double, P, N> c;    ///< C.
  Matrix<double, P, P> r;    ///< R.
};

/// Outcome of the fixed-point iteration.
struct MareOutcome {
  bool converged = false;        ///< max|ΔP| ≤ tol·max|P| reached.
  std::string reason;            ///< "converged", "diverged" (tr P > limit), "not_finite", "iteration_cap".
  std::size_t iterations = 0;    ///< Steps taken.
  double trace = 0;              ///< tr P at the end.
};

/// Iteration settings (the brief's defaults).
struct MareSettings {
  double tolerance = 1e-12;          ///< Relative convergence threshold on max|ΔP|.
  double divergence_trace = 1e15;    ///< tr P above this: diverged.
  std::size_t max_iterations = 2'000'000;  ///< Reaching it counts as diverged (λc ± 1e−4 converges in ~1e5).
};

/// Dense Cholesky of a symmetric n×n (row-major) in place; false at the first pivot ≤ 0
/// or not finite. `min_pivot` receives the smallest pivot (the last one tried on failure).
inline bool cholesky_in_place(std::vector<double>& a, std::size_t n, double& min_pivot) {
  min_pivot = std::numeric_limits<double>::infinity();
  for (std::size_t j = 0; j < n; ++j) {
    double d = a[j * n + j];
    for (std::size_t k = 0; k < j; ++k) d -= a[j * n + k] * a[j * n + k];
    if (d < min_pivot) min_pivot = d;
    if (!(d > 0) || !std::isfinite(d)) {
      min_pivot = d;
      return false;
    }
    const double l = std::sqrt(d);
    a[j * n + j] = l;
    for (std::size_t i = j + 1; i < n; ++i) {
      double s = a[i * n + j];
      for (std::size_t k = 0; k < j; ++k) s -= a[i * n + k] * a[j * n + k];
      a[i * n + j] = s / l;
    }
    for (std::size_t i = 0; i < j; ++i) a[i * n + j] = 0;
  }
  return true;
}

/// Inverse of a small symmetric positive definite matrix (Cholesky); false when not SPD.
template <std::size_t K>
bool spd_inverse(const Matrix<double, K, K>& s, Matrix<double, K, K>& inv) {
  std::vector<double> a(s.data(), s.data() + K * K);
  double piv = 0;
  if (!cholesky_in_place(a, K, piv)) return false;
  for (std::size_t col = 0; col < K; ++col) {
    double x[K];
    for (std::size_t i = 0; i < K; ++i) {  // L z = e_col
      double v = i == col ? 1.0 : 0.0;
      for (std::size_t k = 0; k < i; ++k) v -= a[i * K + k] * x[k];
      x[i] = v / a[i * K + i];
    }
    for (std::size_t ii = K; ii-- > 0;) {  // Lᵀ x = z
      double v = x[ii];
      for (std::size_t k = ii + 1; k < K; ++k) v -= a[k * K + ii] * x[k];
      x[ii] = v / a[ii * K + ii];
    }
    for (std::size_t i = 0; i < K; ++i) inv(i, col) = x[i];
  }
  return true;
}

/// M = Φ P Φᵀ + Q.
template <std::size_t N, std::size_t P>
Matrix<double, N, N> mare_prior(const MareModel<N, P>& m, const Matrix<double, N, N>& p) {
  Matrix<double, N, N> x = m.phi * p * m.phi.transposed() + m.q;
  mirror_upper(x);
  return x;
}

/// K̄(P) = M Cᵀ (C M Cᵀ + R)⁻¹ (18).
template <std::size_t N, std::size_t P>
Matrix<double, N, P> mare_gain(const MareModel<N, P>& m, const Matrix<double, N, N>& p) {
  const Matrix<double, N, N> mm = mare_prior(m, p);
  const Matrix<double, N, P> mct = mm * m.c.transposed();
  Matrix<double, P, P> s = m.c * mct + m.r;
  Matrix<double, P, P> inv;
  if (!spd_inverse(s, inv)) return Matrix<double, N, P>{} * std::numeric_limits<double>::quiet_NaN();
  return mct * inv;
}

/// g_λ(P) = M − λ M Cᵀ (C M Cᵀ + R)⁻¹ C M, mirrored (19); `extra` is added to the diagonal
/// (the certificate's εI).
template <std::size_t N, std::size_t P>
Matrix<double, N, N> mare_map(const MareModel<N, P>& m, const Matrix<double, N, N>& p, double lambda, double extra = 0) {
  const Matrix<double, N, N> mm = mare_prior(m, p);
  const Matrix<double, N, P> mct = mm * m.c.transposed();
  Matrix<double, P, P> s = m.c * mct + m.r;
  Matrix<double, P, P> inv;
  if (!spd_inverse(s, inv)) return Matrix<double, N, N>{} * std::numeric_limits<double>::quiet_NaN();
  Matrix<double, N, N> g = mm - (mct * inv * mct.transposed()) * lambda;
  for (std::size_t i = 0; i < N; ++i) g(i, i) += extra;
  mirror_upper(g);
  return g;
}

/// Iterates P ← g_λ(P) (+ extra·I) from P = 0; `p` receives the last iterate.
template <std::size_t N, std::size_t P>
MareOutcome mare_fixed_point(const MareModel<N, P>& m, double lambda, Matrix<double, N, N>& p,
                             const MareSettings& s = {}, double extra = 0) {
  MareOutcome out;
  p = Matrix<double, N, N>{};
  for (std::size_t it = 1; it <= s.max_iterations; ++it) {
    const Matrix<double, N, N> next = mare_map(m, p, lambda, extra);
    double dmax = 0, pmax = 0, tr = 0;
    bool finite = true;
    for (std::size_t i = 0; i < N * N; ++i) {
      if (!std::isfinite(next[i])) finite = false;
      dmax = std::fmax(dmax, std::fabs(next[i] - p[i]));
      pmax = std::fmax(pmax, std::fabs(next[i]));
    }
    for (std::size_t i = 0; i < N; ++i) tr += next(i, i);
    p = next;
    out.iterations = it;
    out.trace = tr;
    if (!finite) {
      out.reason = "not_finite";
      return out;
    }
    if (tr > s.divergence_trace) {
      out.reason = "diverged";
      return out;
    }
    if (dmax <= s.tolerance * pmax) {
      out.converged = true;
      out.reason = "converged";
      return out;
    }
  }
  out.reason = "iteration_cap";
  return out;
}

/// λ_sys = 1 − 1/ρ², clamped at 0 (28).
inline double lambda_sys_from_radius(double rho) { return rho <= 1 ? 0.0 : 1.0 - 1.0 / (rho * rho); }

/// The bisection's bracket of λc.
struct LambdaCBracket {
  double lo = 0;                    ///< Largest λ tried whose iteration diverged (or λ_sys).
  double hi = 1;                    ///< Smallest λ tried whose iteration converged.
  std::size_t evaluations = 0;      ///< Fixed-point runs.
  std::size_t total_iterations = 0; ///< MARE steps over all runs.
  bool hi_converges = true;         ///< False when even λ = 1 diverges (no bracket).
};

/// λc by bisection of "converges" on [max(λ_sys, 0), 1] until hi − lo ≤ width.
template <std::size_t N, std::size_t P>
LambdaCBracket lambda_c_bisection(const MareModel<N, P>& m, double lambda_sys, double width,
                                  const MareSettings& s = {}) {
  LambdaCBracket b;
  b.lo = lambda_sys > 0 ? lambda_sys : 0;
  b.hi = 1;
  Matrix<double, N, N> p;
  const MareOutcome top = mare_fixed_point(m, 1.0, p, s);
  ++b.evaluations;
  b.total_iterations += top.iterations;
  if (!top.converged) {
    b.hi_converges = false;
    return b;
  }
  while (b.hi - b.lo > width) {
    const double mid = 0.5 * (b.lo + b.hi);
    const MareOutcome o = mare_fixed_point(m, mid, p, s);
    ++b.evaluations;
    b.total_iterations += o.iterations;
    (o.converged ? b.hi : b.lo) = mid;
  }
  return b;
}

/// The certificate's verdict at one λ.
struct Certificate {
  bool certified = false;   ///< The scaled LMI is positive definite at (p, K̄(p)).
  std::string reason;       ///< "certified", "no_fixed_point" (p = g_λ(p) + εI diverged), "cholesky_failed".
  double epsilon = 0;       ///< ε used.
  double min_pivot = 0;     ///< Smallest Cholesky pivot of the scaled matrix (its margin; ≤ 0 on failure).
  std::size_t dimension = 0;  ///< Size of the LMI (5n + p).
};

/// Checks the scaled LMI (23) for the candidate (p, K) at λ by Cholesky.
template <std::size_t N, std::size_t P>
Certificate check_lmi(const MareModel<N, P>& m, double lambda, const Matrix<double, N, N>& p,
                      const Matrix<double, N, P>& k) {
  Certificate c;
  constexpr std::size_t D = 5 * N + P;
  c.dimension = D;
  // Lower Cholesky factors of p, Q, R and their inverses (the congruence).
  auto lower_inverse = [](const auto& a, auto& linv) {
    using Mat = std::decay_t<decltype(a)>;
    constexpr std::size_t K = Mat::kRows;
    std::vector<double> f(a.data(), a.data() + K * K);
    double piv = 0;
    if (!cholesky_in_place(f, K, piv)) return false;
    linv = Mat{};
    for (std::size_t col = 0; col < K; ++col)
      for (std::size_t i = 0; i < K; ++i) {
        double v = i == col ? 1.0 : 0.0;
        for (std::size_t kk = 0; kk < i; ++kk) v -= f[i * K + kk] * linv(kk, col);
        linv(i, col) = v / f[i * K + i];
      }
    return true;
  };
  Matrix<double, N, N> lp, lq;
  Matrix<double, P, P> lr;
  if (!lower_inverse(p, lp) || !lower_inverse(m.q, lq) || !lower_inverse(m.r, lr)) {
    c.reason = "cholesky_failed";
    return c;
  }
  Matrix<double, N, N> a = Matrix<double, N, N>::identity() - k * m.c;
  const double s1 = std::sqrt(1 - lambda), s2 = std::sqrt(lambda);
  // Scaled off-diagonal blocks Lp⁻¹ F_i L_i⁻ᵀ; diagonal blocks become I.
  const Matrix<double, N, N> b1 = lp * (m.phi * p) * lp.transposed() * s1;
  const Matrix<double, N, N> b2 = lp * (a * m.phi * p) * lp.transposed() * s2;
  const Matrix<double, N, N> b3 = lp * m.q * lq.transposed() * s1;
  const Matrix<double, N, N> b4 = lp * (a * m.q) * lq.transposed() * s2;
  const Matrix<double, N, P> b5 = lp * (k * m.r) * lr.transposed() * s2;
  std::vector<double> psi(D * D, 0.0);
  for (std::size_t i = 0; i < D; ++i) psi[i * D + i] = 1.0;
  auto put = [&](std::size_t c0, const auto& b) {
    using Mat = std::decay_t<decltype(b)>;
    for (std::size_t i = 0; i < Mat::kRows; ++i)
      for (std::size_t j = 0; j < Mat::kCols; ++j) {
        psi[i * D + c0 + j] = b(i, j);
        psi[(c0 + j) * D + i] = b(i, j);
      }
  };
  put(N, b1);
  put(2 * N, b2);
  put(3 * N, b3);
  put(4 * N, b4);
  put(5 * N, b5);
  c.certified = cholesky_in_place(psi, D, c.min_pivot);
  c.reason = c.certified ? "certified" : "cholesky_failed";
  return c;
}

/// Certificate at λ: ε = eps_rel·max|P̄_λ| (P̄ the plain fixed point; 1 when it diverges),
/// p = g_λ(p) + εI iterated, K = K̄(p), then check_lmi.
template <std::size_t N, std::size_t P>
Certificate certify(const MareModel<N, P>& m, double lambda, double eps_rel = 1e-6, const MareSettings& s = {}) {
  Matrix<double, N, N> pbar;
  const MareOutcome plain = mare_fixed_point(m, lambda, pbar, s);
  double scale = 1;
  if (plain.converged)
    for (std::size_t i = 0; i < N * N; ++i) scale = std::fmax(scale, std::fabs(pbar[i]));
  const double eps = eps_rel * scale;
  Matrix<double, N, N> p;
  const MareOutcome o = mare_fixed_point(m, lambda, p, s, eps);
  if (!o.converged) {
    Certificate c;
    c.epsilon = eps;
    c.dimension = 5 * N + P;
    c.reason = "no_fixed_point";
    c.min_pivot = std::numeric_limits<double>::quiet_NaN();  // no candidate was factorized
    return c;
  }
  Certificate c = check_lmi(m, lambda, p, mare_gain(m, p));
  c.epsilon = eps;
  return c;
}

}  // namespace oneshot::dropping
