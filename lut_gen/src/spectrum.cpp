/// @file spectrum.cpp
/// @brief Eigenvalues, PBH tests and transmission zeros by LAPACK (see spectrum.hpp).
#include "oneshot/design/spectrum.hpp"

#include "lapack.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "oneshot/design/dense_ops.hpp"

namespace oneshot::design {
namespace {

/// Singular values of a complex rows×cols matrix (row-major), largest first.
std::vector<double> singular_values(std::vector<lapack_complex_double> m, std::size_t rows, std::size_t cols) {
  std::vector<double> s(std::min(rows, cols));
  std::vector<double> superb(s.size() + 1);
  const auto r = static_cast<lapack_int>(rows);
  const auto c = static_cast<lapack_int>(cols);
  if (LAPACKE_zgesvd(LAPACK_ROW_MAJOR, 'N', 'N', r, c, m.data(), c, s.data(), nullptr, 1, nullptr, 1,
                     superb.data()) != 0) {
    throw std::domain_error("PBH test: the singular value decomposition did not converge");
  }
  return s;
}

/// PBH on (A, B): the modes (all, or those with |λ| ≥ 1 − kMarginalTolerance) at which
/// [A − λI, B] loses rank.
ModeCheck pbh(const DenseMatrix& a, const DenseMatrix& b, bool only_unstable) {
  if (a.rows != a.cols || b.rows != a.rows) throw std::logic_error("PBH test: shape mismatch");
  const std::size_t n = a.rows;
  const std::size_t m = b.cols;
  // Rank is invariant under a similarity of A (with B ← D⁻¹B) and a scaling of B's
  // columns: balance A (LAPACK dgebal, powers of two) and give each column of B the norm
  // of A, so that the relative threshold means the same for every plant's units.
  DenseMatrix abal = a;
  std::vector<double> d(n, 1.0);
  lapack_int ilo = 0;
  lapack_int ihi = 0;
  const auto ni = static_cast<lapack_int>(n);
  if (n > 0 && LAPACKE_dgebal(LAPACK_ROW_MAJOR, 'S', ni, abal.values.data(), ni, &ilo, &ihi, d.data()) != 0) {
    abal = a;
    d.assign(n, 1.0);
  }
  DenseMatrix bbal = b;
  const double anorm = std::max(norm_fro(abal), 1e-300);
  for (std::size_t j = 0; j < m; ++j) {
    double col = 0;
    for (std::size_t i = 0; i < n; ++i) {
      bbal(i, j) = b(i, j) / d[i];
      col = std::max(col, std::fabs(bbal(i, j)));
    }
    for (std::size_t i = 0; i < n && col > 0; ++i) bbal(i, j) *= anorm / col;
  }
  DenseMatrix ab = DenseMatrix::zeros(n, n + m);
  set_block(ab, 0, 0, abal);
  set_block(ab, 0, n, bbal);
  std::vector<lapack_complex_double> work(n * (n + m));
  for (std::size_t k = 0; k < ab.values.size(); ++k) work[k] = lapack_complex_double(ab.values[k], 0.0);
  const double scale = singular_values(work, n, n + m).front();
  ModeCheck out;
  for (const std::complex<double>& lambda : eigenvalues(abal)) {
    if (only_unstable && std::abs(lambda) < 1.0 - kMarginalTolerance) continue;
    std::vector<lapack_complex_double> shifted = work;
    for (std::size_t i = 0; i < n; ++i) {
      shifted[i * (n + m) + i] -= lapack_complex_double(lambda.real(), lambda.imag());
    }
    const std::vector<double> s = singular_values(shifted, n, n + m);
    if (!(s.back() > kPbhTolerance * std::max(scale, 1e-300))) {
      out.ok = false;
      out.failing.push_back(lambda);
    }
  }
  return out;
}

}  // namespace

std::vector<std::complex<double>> eigenvalues(const DenseMatrix& a) {
  if (a.rows != a.cols) throw std::logic_error("eigenvalues: not square");
  if (!all_finite(a)) throw std::domain_error("eigenvalues: the matrix is not finite");
  const auto n = static_cast<lapack_int>(a.rows);
  std::vector<std::complex<double>> out;
  if (n == 0) return out;
  DenseMatrix work = a;
  std::vector<double> wr(a.rows);
  std::vector<double> wi(a.rows);
  if (LAPACKE_dgeev(LAPACK_ROW_MAJOR, 'N', 'N', n, work.values.data(), n, wr.data(), wi.data(), nullptr, 1, nullptr,
                    1) != 0) {
    throw std::domain_error("eigenvalues: the QR iteration did not converge");
  }
  for (std::size_t i = 0; i < a.rows; ++i) out.emplace_back(wr[i], wi[i]);
  return out;
}

double spectral_radius(const DenseMatrix& a) {
  double r = 0;
  for (const std::complex<double>& l : eigenvalues(a)) r = std::max(r, std::abs(l));
  return r;
}

std::string ModeCheck::describe() const {
  std::string s;
  for (const std::complex<double>& l : failing) {
    char buf[96];
    if (l.imag() == 0) {
      std::snprintf(buf, sizeof buf, "%s%.10g (|l| = %.10g)", s.empty() ? "" : ", ", l.real(), std::abs(l));
    } else {
      std::snprintf(buf, sizeof buf, "%s%.10g%+.10gi (|l| = %.10g)", s.empty() ? "" : ", ", l.real(), l.imag(),
                    std::abs(l));
    }
    s += buf;
  }
  return s;
}

ModeCheck stabilizable(const DenseMatrix& a, const DenseMatrix& b) { return pbh(a, b, true); }
ModeCheck controllable(const DenseMatrix& a, const DenseMatrix& b) { return pbh(a, b, false); }
ModeCheck detectable(const DenseMatrix& a, const DenseMatrix& c) { return pbh(transpose(a), transpose(c), true); }
ModeCheck observable(const DenseMatrix& a, const DenseMatrix& c) { return pbh(transpose(a), transpose(c), false); }

std::vector<std::complex<double>> transmission_zeros(const DenseMatrix& a, const DenseMatrix& b,
                                                     const DenseMatrix& c, const DenseMatrix& d) {
  const std::size_t n = a.rows;
  const std::size_t m = b.cols;
  if (c.rows != m || d.rows != m || d.cols != m) throw std::invalid_argument("transmission zeros: needs m = p");
  const std::size_t k = n + m;
  DenseMatrix s = DenseMatrix::zeros(k, k);
  set_block(s, 0, 0, a);
  set_block(s, 0, n, b);
  set_block(s, n, 0, c);
  set_block(s, n, n, d);
  DenseMatrix t = DenseMatrix::zeros(k, k);
  set_block(t, 0, 0, identity(n));
  std::vector<double> ar(k), ai(k), beta(k);
  const auto kk = static_cast<lapack_int>(k);
  if (LAPACKE_dggev(LAPACK_ROW_MAJOR, 'N', 'N', kk, s.values.data(), kk, t.values.data(), kk, ar.data(), ai.data(),
                    beta.data(), nullptr, 1, nullptr, 1) != 0) {
    throw std::domain_error("transmission zeros: the QZ iteration did not converge");
  }
  const double scale = std::max({max_abs(a), max_abs(b), max_abs(c), max_abs(d), 1.0});
  std::vector<std::complex<double>> zeros;
  for (std::size_t i = 0; i < k; ++i) {
    const std::complex<double> alpha(ar[i], ai[i]);
    // β ≈ 0 relative to α: an infinite eigenvalue (relative degree), not a zero.
    if (std::fabs(beta[i]) * scale * 1e12 > std::abs(alpha) && beta[i] != 0) zeros.push_back(alpha / beta[i]);
  }
  return zeros;
}

}  // namespace oneshot::design
