/// @file dare.cpp
/// @brief DARE by ordered QZ (see dare.hpp for the method).
#include "oneshot/design/dare.hpp"

#include "lapack.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "oneshot/design/dense_ops.hpp"
#include "oneshot/design/spectrum.hpp"

namespace oneshot::design {
namespace {

/// dgges selection: the generalized eigenvalue α/β lies strictly inside the unit circle.
lapack_logical inside_unit_circle(const double* alphar, const double* alphai, const double* beta) {
  return std::hypot(*alphar, *alphai) < std::fabs(*beta) ? 1 : 0;
}

/// Gain K(X) = (R + BᵀXB)⁻¹(BᵀXA + Sᵀ) (not ok when singular).
SolveResult gain_of(const DenseMatrix& a, const DenseMatrix& b, const DenseMatrix& r, const DenseMatrix& s,
                    const DenseMatrix& x) {
  DenseMatrix rhs = transpose(b) * x * a;
  if (s.rows != 0) rhs = rhs + transpose(s);
  return solve(r + transpose(b) * x * b, rhs, 0.0);
}

/// One Newton (Hewer) step: ΔX solves A_cᵀ ΔX A_c − ΔX = −𝓡(X), A_c = A − B K(X), where
/// 𝓡(X) = AᵀXA − (AᵀXB + S)K(X) + Q − X; the Stein equation is solved through its
/// Kronecker form (A_cᵀ ⊗ A_cᵀ − I) vec ΔX = −vec 𝓡 (n² ≤ 256 unknowns). Empty on failure.
DenseMatrix newton_step(const DenseMatrix& a, const DenseMatrix& b, const DenseMatrix& q, const DenseMatrix& r,
                        const DenseMatrix& s, const DenseMatrix& x) {
  const std::size_t n = a.rows;
  const SolveResult k = gain_of(a, b, r, s, x);
  if (!k.ok) return {};
  DenseMatrix cross = transpose(a) * x * b;
  if (s.rows != 0) cross = cross + s;
  const DenseMatrix res = transpose(a) * x * a - cross * k.x + q - x;
  const DenseMatrix act = transpose(a - b * k.x);  // A_cᵀ
  const std::size_t nn = n * n;
  DenseMatrix kron = DenseMatrix::zeros(nn, nn);
  DenseMatrix rhs = DenseMatrix::zeros(nn, 1);
  // Row-major vec: vec(M)[i n + j] = M(i, j); (A_cᵀ ΔX A_c)(i, j) = Σ act(i, k) ΔX(k, l) act(j, l).
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = 0; j < n; ++j) {
      const std::size_t row = i * n + j;
      for (std::size_t kk = 0; kk < n; ++kk)
        for (std::size_t l = 0; l < n; ++l) kron(row, kk * n + l) = act(i, kk) * act(j, l);
      kron(row, row) -= 1.0;
      rhs(row, 0) = -res(i, j);
    }
  const SolveResult dx = solve(kron, rhs, 0.0);
  if (!dx.ok) return {};
  DenseMatrix next = x;
  for (std::size_t e = 0; e < nn; ++e) next.values[e] += dx.x(e, 0);
  symmetrize(next);
  return next;
}

}  // namespace

const char* to_string(DareStatus s) {
  switch (s) {
    case DareStatus::kOk: return "ok";
    case DareStatus::kInaccurate: return "residual above the accepted limit";
    case DareStatus::kNoStabilizing: return "no stabilising solution (pencil eigenvalues on the unit circle)";
    case DareStatus::kSingularBasis: return "no stabilising solution (singular deflating basis)";
    case DareStatus::kSingularWeight: return "input weight / measurement covariance not invertible";
    case DareStatus::kFailed: return "QZ iteration failed or data not finite";
  }
  return "?";
}

double dare_residual(const DenseMatrix& a, const DenseMatrix& b, const DenseMatrix& q, const DenseMatrix& r,
                     const DenseMatrix& s, const DenseMatrix& x) {
  const DenseMatrix at = transpose(a);
  const DenseMatrix axa = at * x * a;
  DenseMatrix cross = at * x * b;
  if (s.rows != 0) cross = cross + s;
  const SolveResult k = solve(r + transpose(b) * x * b, transpose(cross), 0.0);
  if (!k.ok) return std::numeric_limits<double>::infinity();
  const DenseMatrix correction = cross * k.x;
  const DenseMatrix res = axa - correction + q - x;
  const double scale = norm_fro(q) + norm_fro(axa) + norm_fro(correction);
  return scale > 0 ? norm_fro(res) / scale : norm_fro(res);
}

namespace {

/// QZ on the (σ-scaled) pencil, then Newton refinement; no input checks, no state scaling.
DareSolution solve_core(const DenseMatrix& a, const DenseMatrix& b, const DenseMatrix& q, const DenseMatrix& r,
                        const DenseMatrix& s, const DenseMatrix& r_inv) {
  DareSolution out;
  const std::size_t n = a.rows;
  DenseMatrix a_t = a;
  DenseMatrix q_t = q;
  if (s.rows != 0) {
    a_t = a - b * r_inv * transpose(s);
    q_t = q - s * r_inv * transpose(s);
  }
  DenseMatrix g = b * r_inv * transpose(b);
  symmetrize(g);
  symmetrize(q_t);
  // X = σ X̃ turns (G, Q̃) into (σG, Q̃/σ): balance their norms.
  const double gn = norm_fro(g);
  const double qn = norm_fro(q_t);
  const double sigma = (gn > 0 && qn > 0) ? std::sqrt(qn / gn) : 1.0;

  const std::size_t n2 = 2 * n;
  DenseMatrix lhs = DenseMatrix::zeros(n2, n2);
  DenseMatrix rhs = DenseMatrix::zeros(n2, n2);
  set_block(lhs, 0, 0, a_t);
  set_block(lhs, n, 0, -(q_t * (1.0 / sigma)));
  set_block(lhs, n, n, identity(n));
  set_block(rhs, 0, 0, identity(n));
  set_block(rhs, 0, n, g * sigma);
  set_block(rhs, n, n, transpose(a_t));

  const auto nn = static_cast<lapack_int>(n2);
  lapack_int sdim = 0;
  std::vector<double> ar(n2), ai(n2), beta(n2);
  DenseMatrix vsl = DenseMatrix::zeros(n2, n2);
  DenseMatrix vsr = DenseMatrix::zeros(n2, n2);
  const lapack_int info =
      LAPACKE_dgges(LAPACK_ROW_MAJOR, 'N', 'V', 'S', inside_unit_circle, nn, lhs.values.data(), nn, rhs.values.data(),
                    nn, &sdim, ar.data(), ai.data(), beta.data(), vsl.values.data(), nn, vsr.values.data(), nn);
  if (info != 0 && info != static_cast<lapack_int>(n2) + 2) return out;  // n2+2: reordering rounding, checked below
  out.unit_circle_distance = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < n2; ++i) {
    const double mag = std::hypot(ar[i], ai[i]);
    const double d = beta[i] == 0 ? std::numeric_limits<double>::infinity() : std::fabs(mag / std::fabs(beta[i]) - 1);
    out.unit_circle_distance = std::min(out.unit_circle_distance, d);
  }
  if (sdim != static_cast<lapack_int>(n) || info != 0) {
    out.status = DareStatus::kNoStabilizing;
    return out;
  }
  const DenseMatrix u1 = block(vsr, 0, 0, n, n);
  const DenseMatrix u2 = block(vsr, n, 0, n, n);
  // X̃ = U₂U₁⁻¹ ⇔ U₁ᵀ X̃ᵀ = U₂ᵀ.
  const SolveResult xt = solve(transpose(u1), transpose(u2), 1e-13);
  if (!xt.ok) {
    out.status = DareStatus::kSingularBasis;
    return out;
  }
  out.x = transpose(xt.x) * sigma;
  symmetrize(out.x);
  out.residual = dare_residual(a, b, q, r, s, out.x);
  // Newton refinement while it halves the residual (QZ is backward stable for the pencil,
  // not for the equation: with closed-loop poles within 1e−6 of the unit circle the QZ
  // solution can keep a residual of 1e−4; two or three Newton steps bring it to rounding).
  for (int step = 0; step < 8 && out.residual > 1e-15; ++step) {
    const DenseMatrix next = newton_step(a, b, q, r, s, out.x);
    if (next.rows == 0 || !all_finite(next)) break;
    const double res = dare_residual(a, b, q, r, s, next);
    if (!(res < 0.5 * out.residual)) break;
    out.x = next;
    out.residual = res;
  }
  out.status = DareStatus::kOk;
  return out;
}

/// Diagonal state scaling t (powers of two) from LAPACK's pencil balancing (dggbal) made
/// symplectic: the pencil's column scalings r of x and of the costate give t = √(r_x/r_λ).
std::vector<double> state_scaling(const DenseMatrix& a, const DenseMatrix& g, const DenseMatrix& q) {
  const std::size_t n = a.rows;
  const std::size_t n2 = 2 * n;
  DenseMatrix lhs = DenseMatrix::zeros(n2, n2);
  DenseMatrix rhs = DenseMatrix::zeros(n2, n2);
  set_block(lhs, 0, 0, a);
  set_block(lhs, n, 0, -q);
  set_block(lhs, n, n, identity(n));
  set_block(rhs, 0, 0, identity(n));
  set_block(rhs, 0, n, g);
  set_block(rhs, n, n, transpose(a));
  std::vector<double> lscale(n2), rscale(n2);
  lapack_int ilo = 0;
  lapack_int ihi = 0;
  const auto nn = static_cast<lapack_int>(n2);
  std::vector<double> t(n, 1.0);
  if (LAPACKE_dggbal(LAPACK_ROW_MAJOR, 'S', nn, lhs.values.data(), nn, rhs.values.data(), nn, &ilo, &ihi,
                     lscale.data(), rscale.data()) != 0) {
    return t;
  }
  for (std::size_t i = 0; i < n; ++i) {
    const double ratio = rscale[i] / rscale[n + i];
    if (ratio > 0 && std::isfinite(ratio)) t[i] = std::exp2(std::round(0.5 * std::log2(ratio)));
  }
  return t;
}

}  // namespace

DareSolution solve_dare(const DenseMatrix& a, const DenseMatrix& b, const DenseMatrix& q, const DenseMatrix& r,
                        const DenseMatrix& s) {
  DareSolution out;
  const std::size_t n = a.rows;
  const std::size_t m = b.cols;
  if (a.cols != n || b.rows != n || q.rows != n || q.cols != n || r.rows != m || r.cols != m ||
      (s.rows != 0 && (s.rows != n || s.cols != m))) {
    throw std::logic_error("solve_dare: shape mismatch");
  }
  if (!all_finite(a) || !all_finite(b) || !all_finite(q) || !all_finite(r) || !all_finite(s)) return out;
  const SolveResult r_inv = solve(r, identity(m));
  if (!r_inv.ok) {
    out.status = DareStatus::kSingularWeight;
    return out;
  }
  // State scaling x = T x̃: Ã = T⁻¹AT, B̃ = T⁻¹B, Q̃ = TQT, S̃ = TS, X = T⁻¹X̃T⁻¹. States whose
  // variances or weights differ by many decades (a disturbance model behind a gain of 1e5)
  // otherwise leave the small entries of X below the rounding level of the large ones.
  DenseMatrix g = b * r_inv.x * transpose(b);
  const std::vector<double> t = state_scaling(a, g, q);
  DenseMatrix as = a, bs = b, qs = q, ss = s;
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = 0; j < n; ++j) {
      as(i, j) = a(i, j) * t[j] / t[i];
      qs(i, j) = q(i, j) * t[i] * t[j];
    }
    for (std::size_t j = 0; j < m; ++j) {
      bs(i, j) = b(i, j) / t[i];
      if (s.rows != 0) ss(i, j) = s(i, j) * t[i];
    }
  }
  out = solve_core(as, bs, qs, r, ss, r_inv.x);
  if (out.status != DareStatus::kOk) return out;
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = 0; j < n; ++j) out.x(i, j) = out.x(i, j) / (t[i] * t[j]);
  out.residual = dare_residual(a, b, q, r, s, out.x);
  const SolveResult k = gain_of(a, b, r, s, out.x);
  if (!k.ok) {
    out.status = DareStatus::kSingularBasis;
    return out;
  }
  out.closed_loop_radius = spectral_radius(a - b * k.x);
  if (!(out.closed_loop_radius < 1.0)) {
    out.status = DareStatus::kNoStabilizing;
  } else {
    out.status = out.residual <= kDareResidualLimit ? DareStatus::kOk : DareStatus::kInaccurate;
  }
  return out;
}

}  // namespace oneshot::design
