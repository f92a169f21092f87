/// @file dense_ops.hpp
/// @brief Run-time sized linear algebra on DenseMatrix for the design step (host only).
///
/// The design step works on plants of any size up to the limits of dimension_limits.hpp
/// without instantiating a template per (n, m, p): products, blocks, LU solves (LAPACK
/// dgesv with a condition estimate) and the matrix exponential, all on row-major doubles.
#pragma once

#include <cstddef>
#include <string>

#include "oneshot/design/dense_matrix.hpp"

namespace oneshot::design {

/// n×n identity.
DenseMatrix identity(std::size_t n);
/// Aᵀ.
DenseMatrix transpose(const DenseMatrix& a);
/// A·B (inner dimensions checked: std::logic_error), summed left to right like the core.
DenseMatrix operator*(const DenseMatrix& a, const DenseMatrix& b);
/// A·s entry-wise.
DenseMatrix operator*(const DenseMatrix& a, double s);
/// A + B (shapes checked).
DenseMatrix operator+(const DenseMatrix& a, const DenseMatrix& b);
/// A − B (shapes checked).
DenseMatrix operator-(const DenseMatrix& a, const DenseMatrix& b);
/// −A.
DenseMatrix operator-(const DenseMatrix& a);

/// rows×cols block of A starting at (r0, c0).
DenseMatrix block(const DenseMatrix& a, std::size_t r0, std::size_t c0, std::size_t rows, std::size_t cols);
/// Writes B into A at (r0, c0).
void set_block(DenseMatrix& a, std::size_t r0, std::size_t c0, const DenseMatrix& b);
/// The rows of A listed in `rows`, in that order.
DenseMatrix select_rows(const DenseMatrix& a, const std::vector<std::size_t>& rows);

/// max |a_ij| (0 for an empty matrix).
double max_abs(const DenseMatrix& a);
/// ‖A‖₁: largest absolute column sum.
double norm1(const DenseMatrix& a);
/// Frobenius norm, scaled against overflow.
double norm_fro(const DenseMatrix& a);
/// True when every entry is finite.
bool all_finite(const DenseMatrix& a);
/// A ← (A + Aᵀ)/2 (square A).
void symmetrize(DenseMatrix& a);
/// Entries below `tiny`·max|A| in magnitude become exact zeros (no −0 or rounding dust).
void flush_tiny(DenseMatrix& a, double tiny);

/// Result of a linear solve.
struct SolveResult {
  bool ok = false;        ///< False when A is singular or its reciprocal condition is below the limit.
  double rcond = 0;       ///< Reciprocal 1-norm condition estimate of the equilibrated A (LAPACK dgecon).
  DenseMatrix x;          ///< A⁻¹B when ok.
};

/// X = A⁻¹B by LU with partial pivoting (LAPACK dgetrf/dgetrs) of A equilibrated by exact
/// powers of two (rows, then columns); not ok when the equilibrated rcond < min_rcond.
SolveResult solve(const DenseMatrix& a, const DenseMatrix& b, double min_rcond = 1e-14);

/// e^M by scaling and squaring with the Taylor polynomial of the core's
/// matrix_exponential.hpp (‖M‖₁·2⁻ˢ ≤ 1/2, same degree, same operation order), so a plant
/// the core also discretizes gets bit-identical Φ, Γ. Throws std::domain_error when ‖M‖₁
/// needs more than the core's kMaxSquarings halvings or M is not finite; `what` names it.
DenseMatrix expm(const DenseMatrix& m, const std::string& what);

}  // namespace oneshot::design
