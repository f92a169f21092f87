/// @file dare.cpp
/// @brief DARE by ordered QZ (see dare.hpp for the method).
#include "oneshot/design/dare.hpp"

#include "lapack.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "oneshot/design/dense_ops.hpp"

namespace oneshot::design {
namespace {

/// dgges selection: the generalized eigenvalue α/β lies strictly inside the unit circle.
lapack_logical inside_unit_circle(const double* alphar, const double* alphai, const double* beta) {
  return std::hypot(*alphar, *alphai) < std::fabs(*beta) ? 1 : 0;
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
  DenseMatrix a_t = a;
  DenseMatrix q_t = q;
  if (s.rows != 0) {
    a_t = a - b * r_inv.x * transpose(s);
    q_t = q - s * r_inv.x * transpose(s);
  }
  DenseMatrix g = b * r_inv.x * transpose(b);
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
  out.status = out.residual <= kDareResidualLimit ? DareStatus::kOk : DareStatus::kInaccurate;
  return out;
}

}  // namespace oneshot::design
