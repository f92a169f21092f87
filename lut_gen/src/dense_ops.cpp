/// @file dense_ops.cpp
/// @brief Run-time sized linear algebra for the design step (see dense_ops.hpp).
#include "oneshot/design/dense_ops.hpp"

#include "lapack.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include "oneshot/matrix_exponential.hpp"
#include "oneshot/scalar_traits.hpp"

namespace oneshot::design {
namespace {

void require_same_shape(const DenseMatrix& a, const DenseMatrix& b, const char* op) {
  if (a.rows != b.rows || a.cols != b.cols) throw std::logic_error(std::string("dense ") + op + ": shape mismatch");
}

}  // namespace

DenseMatrix identity(std::size_t n) {
  DenseMatrix m = DenseMatrix::zeros(n, n);
  for (std::size_t i = 0; i < n; ++i) m(i, i) = 1.0;
  return m;
}

DenseMatrix transpose(const DenseMatrix& a) {
  DenseMatrix t = DenseMatrix::zeros(a.cols, a.rows);
  for (std::size_t i = 0; i < a.rows; ++i)
    for (std::size_t j = 0; j < a.cols; ++j) t(j, i) = a(i, j);
  return t;
}

DenseMatrix operator*(const DenseMatrix& a, const DenseMatrix& b) {
  if (a.cols != b.rows) throw std::logic_error("dense product: inner dimensions differ");
  DenseMatrix p = DenseMatrix::zeros(a.rows, b.cols);
  if (a.cols == 0) return p;
  for (std::size_t i = 0; i < a.rows; ++i)
    for (std::size_t j = 0; j < b.cols; ++j) {
      double acc = a(i, 0) * b(0, j);  // same order as the core's Matrix product
      for (std::size_t k = 1; k < a.cols; ++k) acc = acc + a(i, k) * b(k, j);
      p(i, j) = acc;
    }
  return p;
}

DenseMatrix operator*(const DenseMatrix& a, double s) {
  DenseMatrix r = a;
  for (double& v : r.values) v = v * s;
  return r;
}

DenseMatrix operator+(const DenseMatrix& a, const DenseMatrix& b) {
  require_same_shape(a, b, "sum");
  DenseMatrix r = a;
  for (std::size_t k = 0; k < r.values.size(); ++k) r.values[k] = a.values[k] + b.values[k];
  return r;
}

DenseMatrix operator-(const DenseMatrix& a, const DenseMatrix& b) {
  require_same_shape(a, b, "difference");
  DenseMatrix r = a;
  for (std::size_t k = 0; k < r.values.size(); ++k) r.values[k] = a.values[k] - b.values[k];
  return r;
}

DenseMatrix operator-(const DenseMatrix& a) {
  DenseMatrix r = a;
  for (double& v : r.values) v = -v;
  return r;
}

DenseMatrix block(const DenseMatrix& a, std::size_t r0, std::size_t c0, std::size_t rows, std::size_t cols) {
  if (r0 + rows > a.rows || c0 + cols > a.cols) throw std::logic_error("dense block: out of range");
  DenseMatrix b = DenseMatrix::zeros(rows, cols);
  for (std::size_t i = 0; i < rows; ++i)
    for (std::size_t j = 0; j < cols; ++j) b(i, j) = a(r0 + i, c0 + j);
  return b;
}

void set_block(DenseMatrix& a, std::size_t r0, std::size_t c0, const DenseMatrix& b) {
  if (r0 + b.rows > a.rows || c0 + b.cols > a.cols) throw std::logic_error("dense set_block: out of range");
  for (std::size_t i = 0; i < b.rows; ++i)
    for (std::size_t j = 0; j < b.cols; ++j) a(r0 + i, c0 + j) = b(i, j);
}

DenseMatrix select_rows(const DenseMatrix& a, const std::vector<std::size_t>& rows) {
  DenseMatrix r = DenseMatrix::zeros(rows.size(), a.cols);
  for (std::size_t i = 0; i < rows.size(); ++i) set_block(r, i, 0, block(a, rows[i], 0, 1, a.cols));
  return r;
}

double max_abs(const DenseMatrix& a) {
  double m = 0;
  for (double v : a.values) m = std::max(m, std::fabs(v));
  return m;
}

double norm1(const DenseMatrix& a) {
  double best = 0;
  for (std::size_t j = 0; j < a.cols; ++j) {
    double s = 0;
    for (std::size_t i = 0; i < a.rows; ++i) s += std::fabs(a(i, j));
    best = std::max(best, s);
  }
  return best;
}

double norm_fro(const DenseMatrix& a) {
  const double scale = max_abs(a);
  if (!(scale > 0) || !std::isfinite(scale)) return scale;
  double s = 0;
  for (double v : a.values) s += (v / scale) * (v / scale);  // scaled: no overflow, no underflow to 0
  return scale * std::sqrt(s);
}

bool all_finite(const DenseMatrix& a) {
  return std::all_of(a.values.begin(), a.values.end(), [](double v) { return std::isfinite(v); });
}

void symmetrize(DenseMatrix& a) {
  for (std::size_t i = 0; i < a.rows; ++i)
    for (std::size_t j = i + 1; j < a.cols; ++j) a(i, j) = a(j, i) = 0.5 * (a(i, j) + a(j, i));
}

void flush_tiny(DenseMatrix& a, double tiny) {
  const double limit = tiny * max_abs(a);
  for (double& v : a.values) v = std::fabs(v) <= limit ? 0.0 : v;
}

SolveResult solve(const DenseMatrix& a, const DenseMatrix& b, double min_rcond) {
  if (a.rows != a.cols || b.rows != a.rows) throw std::logic_error("dense solve: shape mismatch");
  SolveResult r;
  const std::size_t n = a.rows;
  const auto ni = static_cast<lapack_int>(n);
  const auto k = static_cast<lapack_int>(b.cols);
  if (n == 0 || !all_finite(a) || !all_finite(b)) return r;
  // Equilibrate with powers of two (exact): rows by their largest entry, then columns, so a
  // badly scaled but regular matrix (entries from 1e−5 to 1e5) is not called singular.
  std::vector<double> row(n, 1.0);
  std::vector<double> col(n, 1.0);
  for (std::size_t i = 0; i < n; ++i) {
    double big = 0;
    for (std::size_t j = 0; j < n; ++j) big = std::max(big, std::fabs(a(i, j)));
    if (big > 0) row[i] = std::exp2(-std::round(std::log2(big)));
  }
  for (std::size_t j = 0; j < n; ++j) {
    double big = 0;
    for (std::size_t i = 0; i < n; ++i) big = std::max(big, std::fabs(a(i, j) * row[i]));
    if (big > 0) col[j] = std::exp2(-std::round(std::log2(big)));
  }
  DenseMatrix lu = a;
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = 0; j < n; ++j) lu(i, j) = a(i, j) * row[i] * col[j];
  r.x = b;
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = 0; j < b.cols; ++j) r.x(i, j) = b(i, j) * row[i];
  std::vector<lapack_int> pivots(n);
  const double anorm = norm1(lu);
  if (LAPACKE_dgetrf(LAPACK_ROW_MAJOR, ni, ni, lu.values.data(), ni, pivots.data()) != 0) return r;
  if (LAPACKE_dgecon(LAPACK_ROW_MAJOR, '1', ni, lu.values.data(), ni, anorm, &r.rcond) != 0) return r;
  if (!(r.rcond >= min_rcond)) return r;
  if (k > 0 &&
      LAPACKE_dgetrs(LAPACK_ROW_MAJOR, 'N', ni, k, lu.values.data(), ni, pivots.data(), r.x.values.data(), k) != 0) {
    return r;
  }
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = 0; j < b.cols; ++j) r.x(i, j) = r.x(i, j) * col[i];
  r.ok = all_finite(r.x);
  return r;
}

DenseMatrix expm(const DenseMatrix& m, const std::string& what) {
  if (m.rows != m.cols) throw std::logic_error("expm: not square");
  if (!all_finite(m)) throw std::domain_error(what + ": the matrix to exponentiate is not finite");
  // Mirrors oneshot::matrix_exponential<double>: Taylor degree, θ = 1/2, Horner order.
  constexpr int kDegree = ScalarTraits<double>::kTaylorDegree;
  DenseMatrix x = m;
  double norm = 0;
  for (std::size_t j = 0; j < m.cols; ++j) {
    double col = 0;
    for (std::size_t i = 0; i < m.rows; ++i) col = col + std::fabs(m(i, j));
    if (norm < col) norm = col;
  }
  int squarings = 0;
  while (0.5 < norm) {
    if (++squarings > kMaxSquarings) {
      throw std::domain_error(what + ": the norm " + std::to_string(norm) + " is too large for the exponential");
    }
    norm = norm * 0.5;
    x = x * 0.5;
  }
  const DenseMatrix eye = identity(m.rows);
  DenseMatrix e = eye;
  for (int k = kDegree; k >= 1; --k) e = eye + (x * e) * (1.0 / static_cast<double>(k));
  for (int s = 0; s < squarings; ++s) e = e * e;
  return e;
}

}  // namespace oneshot::design
