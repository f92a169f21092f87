/// @file spectrum.hpp
/// @brief Eigenvalues, spectral radius, PBH mode tests and transmission zeros (host).
///
/// Eigenvalues come from LAPACK's dgeev (balancing, Hessenberg reduction, shifted QR):
/// backward stable for any n, unlike the characteristic polynomial (Faddeev–LeVerrier)
/// whose coefficients lose every digit past n ≈ 4 for poles clustered near 1.
///
/// PBH (Popov–Belevitch–Hautus): a mode λ of A is uncontrollable from B iff
/// rank [A − λI, B] < n; it is tested by the smallest singular value of that complex
/// matrix against kPbhTolerance·‖[A, B]‖₂. Stabilizability checks the modes with
/// |λ| ≥ 1 − kMarginalTolerance (marginal modes count as unstable); detectability is the
/// dual test on (Aᵀ, Cᵀ).
#pragma once

#include <complex>
#include <string>
#include <vector>

#include "oneshot/design/dense_matrix.hpp"

namespace oneshot::design {

/// Relative singular-value level below which [A − λI, B] counts as rank deficient.
inline constexpr double kPbhTolerance = 1e-9;
/// Modes with |λ| ≥ 1 − this are treated as not asymptotically stable.
inline constexpr double kMarginalTolerance = 1e-10;

/// Eigenvalues of a square matrix (dgeev); std::domain_error when it does not converge
/// or A is not finite.
std::vector<std::complex<double>> eigenvalues(const DenseMatrix& a);

/// max |λ_i(A)|.
double spectral_radius(const DenseMatrix& a);

/// Modes of A that fail a PBH test.
struct ModeCheck {
  bool ok = true;                                ///< No failing mode.
  std::vector<std::complex<double>> failing;     ///< The failing eigenvalues.
  /// "λ = 1 (|λ| = 1)" style list of the failing modes, for error messages.
  std::string describe() const;
};

/// (A, B) stabilizable: every mode with |λ| ≥ 1 − kMarginalTolerance is controllable.
ModeCheck stabilizable(const DenseMatrix& a, const DenseMatrix& b);
/// (A, B) controllable: every mode is.
ModeCheck controllable(const DenseMatrix& a, const DenseMatrix& b);
/// (A, C) detectable: every mode with |λ| ≥ 1 − kMarginalTolerance is observable.
ModeCheck detectable(const DenseMatrix& a, const DenseMatrix& c);
/// (A, C) observable: every mode is.
ModeCheck observable(const DenseMatrix& a, const DenseMatrix& c);

/// Finite transmission zeros of the square plant (A, B, C, D) (m = p): the finite
/// generalized eigenvalues of the Rosenbrock pencil [[A, B], [C, D]] − z [[I, 0], [0, 0]]
/// (LAPACK dggev). std::invalid_argument when m ≠ p.
std::vector<std::complex<double>> transmission_zeros(const DenseMatrix& a, const DenseMatrix& b,
                                                     const DenseMatrix& c, const DenseMatrix& d);

}  // namespace oneshot::design
