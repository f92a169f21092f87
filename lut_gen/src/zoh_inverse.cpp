/// @file zoh_inverse.cpp
/// @brief The exact inverse of zero-order-hold sampling (see zoh_inverse.hpp).
#include "oneshot/design/zoh_inverse.hpp"

#include <cmath>
#include <complex>
#include <limits>
#include <sstream>
#include <utility>
#include <vector>

#include "oneshot/design/dense_ops.hpp"
#include "oneshot/design/spectrum.hpp"

namespace oneshot::design {
namespace {

/// Halvings of Γ at most (2¹⁰⁷⁴ spans every finite double ratio ‖Γ‖₁/room).
constexpr int kMaxGammaHalvings = 2100;
/// Reciprocal condition below which an iterate or a map is singular to working precision (about
/// 90 ulps: LAPACK's estimate is within a small factor of the true one).
constexpr double kSingularRcond = 1e-14;
/// Entries of Q_c below this times max |Q_c| are rounding dust of the solve (≈ 90 ulps of the
/// largest), flushed to exact zeros so a rank-deficient intensity stays rank-deficient.
constexpr double kQcDust = 1e-14;
/// Q_c is positive semidefinite when its smallest eigenvalue ≥ −this·max |Q_c|: rounding of the
/// solve and of the eigenvalues (≈ 10⁴ of kQcDust) is not a negative intensity.
constexpr double kQcPsdTolerance = 1e-10;
/// A failed logarithm or reconstruction names the eigenvalue of Φ closest to the negative real
/// axis as the cause when it lies within this angle δ (rad) of it: the first Denman–Beavers step
/// takes it to (1 + cos(π − δ))/2 ≈ δ²/4, an iterate whose inverse amplifies rounding by ≈ 4/δ²
/// at most (measured on rotations by π − δ: a singular iterate for δ ≤ 1e−8, Φ given back off
/// by 8.9e−5 at δ = 1e−6, 5.3e−9 at 1e−4, 1.6e−11 at 1e−3, accepted): within 1e−2 it is the
/// likely cause of a failure (4/δ² ≥ 4·10⁴ ulps).
constexpr double kNearNegativeAxisRad = 1e-2;

/// X⁻¹, or LogmError (singular iterate) when X is singular to working precision.
DenseMatrix inverse_of(const DenseMatrix& x) {
  const SolveResult r = solve(x, identity(x.rows), kSingularRcond);
  if (!r.ok) throw LogmError(LogmError::Failure::kSingularIterate, "a Denman-Beavers square root met a singular iterate");
  return r.x;
}

/// X^{1/2} by the product form of the Denman–Beavers iteration (Higham, Functions of Matrices,
/// eq. 6.17): M₀ = Y₀ = X, M ← (I + (M + M⁻¹)/2)/2, Y ← Y(I + M⁻¹)/2; M → I, Y → X^{1/2}.
/// Stops one iteration after ‖M − I‖₁ ≤ kSquareRootStop (quadratic convergence: that one is at rounding).
DenseMatrix square_root(const DenseMatrix& x) {
  const DenseMatrix eye = identity(x.rows);
  DenseMatrix m = x;
  DenseMatrix y = x;
  bool last = false;
  for (int k = 0; k < kSquareRootMaxIterations; ++k) {
    const DenseMatrix m_inv = inverse_of(m);
    y = (y * (eye + m_inv)) * 0.5;
    m = (eye + (m + m_inv) * 0.5) * 0.5;
    if (last) return y;
    last = norm1(m - eye) <= kSquareRootStop;
  }
  throw LogmError(LogmError::Failure::kNoConvergence, "a Denman-Beavers square root did not converge in " +
                                                          std::to_string(kSquareRootMaxIterations) + " iterations");
}

std::string complex_text(std::complex<double> z) {
  std::ostringstream o;
  o.precision(6);
  o << z.real();
  if (z.imag() != 0) o << (z.imag() < 0 ? " - " : " + ") << std::fabs(z.imag()) << "i";
  return o.str();
}

/// ∫₀ʰ e^{As}·Q·e^{Aᵀs} ds as a linear map on row-major vec Q: the top-right block of
/// exp([[L, I], [0, 0]]h) with L = A ⊗ I + I ⊗ A.
DenseMatrix van_loan_map(const DenseMatrix& a, double h) {
  const std::size_t n = a.rows;
  const std::size_t k = n * n;
  DenseMatrix big = DenseMatrix::zeros(2 * k, 2 * k);
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = 0; j < n; ++j)
      for (std::size_t l = 0; l < n; ++l) {
        big(i * n + j, l * n + j) += a(i, l) * h;  // (A X)_ij = Σ_l A_il X_lj
        big(i * n + j, i * n + l) += a(j, l) * h;  // (X Aᵀ)_ij = Σ_l X_il A_jl
      }
  for (std::size_t i = 0; i < k; ++i) big(i, k + i) = h;
  return block(expm(big, "d2c: the Van Loan map of the noise"), 0, k, k, k);
}

/// The refusal of Φ whose eigenvalues `spectrum` have no (unique) real logarithm, if one has
/// none: at 0 (|λ| ≤ kZohInverseTolerance·max(1, ‖Φ‖₁)), or on the closed negative real axis.
void refuse_spectrum(const std::vector<std::complex<double>>& spectrum, double phi_norm) {
  using Part = ZohInverseError::Part;
  const double scale = std::fmax(1.0, phi_norm);
  for (const std::complex<double>& lambda : spectrum) {
    if (std::abs(lambda) <= kZohInverseTolerance * scale) {
      throw ZohInverseError(Part::kPhi, "singular (eigenvalue " + complex_text(lambda) +
                                            "): no logarithm, so no continuous plant samples to it");
    }
    if (lambda.real() < 0 && std::fabs(lambda.imag()) <= kZohInverseTolerance * std::abs(lambda)) {
      throw ZohInverseError(Part::kPhi, "eigenvalue " + complex_text(lambda) +
                                            " on the negative real axis: no real principal logarithm, so no unique "
                                            "continuous plant samples to it");
    }
  }
}

/// The eigenvalue of `spectrum` nearest the negative real axis and its angle from it (rad).
std::pair<std::complex<double>, double> nearest_negative_axis(const std::vector<std::complex<double>>& spectrum) {
  std::pair<std::complex<double>, double> best{{}, std::numeric_limits<double>::infinity()};
  for (const std::complex<double>& lambda : spectrum) {
    const double off_axis = std::acos(-1.0) - std::fabs(std::arg(lambda));  // π − |arg λ|
    if (off_axis < best.second) best = {lambda, off_axis};
  }
  return best;
}

/// "eigenvalue λ lies δ rad from the negative real axis, …" when δ ≤ kNearNegativeAxisRad, else empty.
std::string near_axis_text(const std::vector<std::complex<double>>& spectrum) {
  const auto [lambda, off_axis] = nearest_negative_axis(spectrum);
  if (!(off_axis <= kNearNegativeAxisRad)) return {};
  std::ostringstream o;
  o.precision(3);
  o << "eigenvalue " << complex_text(lambda) << " lies " << off_axis
    << " rad from the negative real axis (the square roots lose up to 4/angle^2 ulps near it; on it no real principal "
       "logarithm exists)";
  return o.str();
}

/// The refusal of Φ when logm() failed with `e`: the eigenvalue nearest the negative real axis
/// when it is within kNearNegativeAxisRad (the cause), else the iteration that did not converge.
ZohInverseError logm_refusal(const std::vector<std::complex<double>>& spectrum, const LogmError& e) {
  std::string why = near_axis_text(spectrum);
  if (why.empty()) {
    const auto [lambda, off_axis] = nearest_negative_axis(spectrum);
    std::ostringstream o;
    o.precision(3);
    o << "no convergence, with no eigenvalue near the negative real axis (the nearest, " << complex_text(lambda) << ", "
      << off_axis << " rad from it): Phi too far from normal for the square roots";
    why = o.str();
  }
  return {ZohInverseError::Part::kPhi, "the principal logarithm failed (" + std::string(e.what()) + "): " + why};
}

/// ‖got − want‖₁ / ‖want‖₁; when want = 0, 0 if got is 0 too, else +∞.
double block_error(const DenseMatrix& got, const DenseMatrix& want) {
  const double diff = norm1(got - want);
  const double scale = norm1(want);
  if (scale > 0) return diff / scale;
  return diff == 0 ? 0.0 : std::numeric_limits<double>::infinity();
}

/// The refusal text of a block off by `error` (relative to its own norm).
std::string off_by(const char* what, double error) {
  std::ostringstream o;
  o << "the continuous plant from the logarithm samples back to " << what << " with a relative error " << error
    << " (above " << kZohInverseMaxError << "): no accurate continuous equivalent";
  return o.str();
}

/// κ₁(Φ) = ‖Φ‖₁‖Φ⁻¹‖₁ (+∞ when Φ is singular to the solver).
double condition_1(const DenseMatrix& phi, double phi_norm) {
  const SolveResult r = solve(phi, identity(phi.rows), 0.0);
  return r.ok ? phi_norm * norm1(r.x) : std::numeric_limits<double>::infinity();
}

}  // namespace

DenseMatrix logm(const DenseMatrix& m, int* square_roots) {
  if (m.rows != m.cols) throw std::logic_error("logm: not square");
  const DenseMatrix eye = identity(m.rows);
  DenseMatrix x = m;
  int s = 0;
  while (!(norm1(x - eye) < kLogmSeriesRadius)) {
    if (++s > kLogmMaxSquareRoots) {
      throw LogmError(LogmError::Failure::kTooManyRoots, "X - I does not fall below 1/4 in " +
                                                             std::to_string(kLogmMaxSquareRoots) + " square roots");
    }
    x = square_root(x);
  }
  // log(I + Y) = Σ_{k ≥ 1} (−1)^{k+1} Yᵏ/k, ‖Y‖₁ < 1/4: 40 terms leave < 4^{−41}/41 (Horner).
  const DenseMatrix y = x - eye;
  DenseMatrix acc = eye * ((kLogmSeriesTerms % 2 == 1 ? 1.0 : -1.0) / kLogmSeriesTerms);
  for (int k = kLogmSeriesTerms - 1; k >= 1; --k) acc = eye * ((k % 2 == 1 ? 1.0 : -1.0) / k) + y * acc;
  if (square_roots != nullptr) *square_roots = s;
  return (y * acc) * std::ldexp(1.0, s);
}

ZohReconstruction check_zoh_reconstruction(const DenseMatrix& phi, const DenseMatrix& gamma, const DenseMatrix& a,
                                           const DenseMatrix& b, double h_s) {
  const std::size_t n = phi.rows;
  const std::size_t m = gamma.cols;
  DenseMatrix aug = DenseMatrix::zeros(n + m, n + m);
  set_block(aug, 0, 0, phi);
  set_block(aug, 0, n, gamma);
  set_block(aug, n, n, identity(m));
  DenseMatrix f = DenseMatrix::zeros(n + m, n + m);
  set_block(f, 0, 0, a * h_s);
  set_block(f, 0, n, b * h_s);
  const DenseMatrix back = expm(f, "d2c: the reconstruction exp([[A, B], [0, 0]] h)");
  ZohReconstruction r;
  r.relative_error = norm1(back - aug) / norm1(aug);
  // Γ(A, B, h) is linear in B and so is every operation of the exponential on that block: its
  // error is relative to ‖Γ‖, and checked so (the whole-matrix error scales it by ‖Γ‖/‖M‖).
  r.phi_relative_error = block_error(block(back, 0, 0, n, n), phi);
  r.gamma_relative_error = block_error(block(back, 0, n, n, m), gamma);
  using Part = ZohInverseError::Part;
  if (!(r.phi_relative_error <= kZohInverseMaxError)) throw ZohInverseError(Part::kPhi, off_by("Phi", r.phi_relative_error));
  if (!(r.gamma_relative_error <= kZohInverseMaxError)) {
    throw ZohInverseError(Part::kGamma, off_by("Gamma", r.gamma_relative_error));
  }
  return r;
}

ZohInverse zoh_inverse(const DenseMatrix& phi, const DenseMatrix& gamma, double h_s, const DenseMatrix& qd) {
  using Part = ZohInverseError::Part;
  const std::size_t n = phi.rows;
  const std::size_t m = gamma.cols;
  if (phi.cols != n || gamma.rows != n || !(h_s > 0)) throw std::logic_error("zoh_inverse: bad shapes or period");
  const double phi_norm = norm1(phi);
  const std::vector<std::complex<double>> spectrum = eigenvalues(phi);
  refuse_spectrum(spectrum, phi_norm);
  ZohInverse r;
  // σ = 2ᵏ ≥ 1 (exact): log [[Φ, Γ/σ], [0, I]] = [[Ah, Bh/σ], [0, 0]], ‖Γ/σ‖₁ within the room
  // Φ leaves, so that Γ adds a square root or two at most (‖M − I‖₁ = max(‖Φ − I‖₁, ‖Γ/σ‖₁)).
  const double room = std::fmax(2.0 * norm1(phi - identity(n)), kLogmSeriesRadius / 2);
  const double gamma_norm = norm1(gamma);
  for (int k = 0; k < kMaxGammaHalvings && gamma_norm / r.gamma_scale > room; ++k) r.gamma_scale *= 2;
  DenseMatrix aug = DenseMatrix::zeros(n + m, n + m);
  set_block(aug, 0, 0, phi);
  set_block(aug, 0, n, gamma * (1.0 / r.gamma_scale));
  set_block(aug, n, n, identity(m));
  DenseMatrix log_m;
  try {
    log_m = logm(aug, &r.square_roots);
  } catch (const LogmError& e) {
    throw logm_refusal(spectrum, e);
  }
  // The bottom rows of log M are 0 in exact arithmetic: the continuous model has them 0.
  r.a = block(log_m, 0, 0, n, n) * (1.0 / h_s);
  r.b = block(log_m, 0, n, n, m) * (r.gamma_scale / h_s);
  ZohReconstruction back;
  try {
    back = check_zoh_reconstruction(phi, gamma, r.a, r.b, h_s);
  } catch (const ZohInverseError& e) {  // with the likely cause, when an eigenvalue is near the negative real axis
    const std::string why = near_axis_text(spectrum);
    if (why.empty()) throw;
    throw ZohInverseError(e.part(), std::string(e.what()) + "; " + why);
  }
  r.relative_error = back.relative_error;
  r.phi_relative_error = back.phi_relative_error;
  r.gamma_relative_error = back.gamma_relative_error;
  r.phi_condition = condition_1(phi, phi_norm);
  if (qd.rows == 0) return r;
  // Q_d = ∫₀ʰ e^{As} Q_c e^{Aᵀs} ds is linear in Q_c, and regular for the principal A (the
  // eigenvalues λᵢ + λⱼ of L have |Im| < 2π/h): solve it on vec Q_c.
  const std::size_t k = n * n;
  const DenseMatrix map = van_loan_map(r.a, h_s);
  const SolveResult sol = solve(map, DenseMatrix{k, 1, qd.values}, kSingularRcond);
  if (!sol.ok) throw ZohInverseError(Part::kNoise, "the Van Loan map of the continuous equivalent is singular");
  r.qc = DenseMatrix{n, n, sol.x.values};
  symmetrize(r.qc);
  flush_tiny(r.qc, kQcDust);
  double min_eig = 0;
  for (const std::complex<double>& lambda : eigenvalues(r.qc)) min_eig = std::fmin(min_eig, lambda.real());
  if (min_eig < -kQcPsdTolerance * max_abs(r.qc)) {
    std::ostringstream o;
    o << "the continuous intensity Q_c whose sampling at h gives it is not positive semidefinite (eigenvalue "
      << min_eig << "): no white-noise continuous plant has this per-step covariance";
    throw ZohInverseError(Part::kNoise, o.str());
  }
  // Checked by the other path, the one sample_plant() takes: exp([[−A, Q_c], [0, Aᵀ]]h).
  DenseMatrix vl = DenseMatrix::zeros(2 * n, 2 * n);
  set_block(vl, 0, 0, -r.a * h_s);
  set_block(vl, 0, n, r.qc * h_s);
  set_block(vl, n, n, transpose(r.a) * h_s);
  const DenseMatrix e = expm(vl, "d2c: the Van Loan check of Q_c");
  const DenseMatrix qd_back = transpose(block(e, n, n, n, n)) * block(e, 0, n, n, n);
  const double qd_norm = norm1(qd);
  r.noise_relative_error = qd_norm > 0 ? norm1(qd_back - qd) / qd_norm : 0.0;
  if (!(r.noise_relative_error <= kZohInverseMaxError)) {
    std::ostringstream o;
    o << "the continuous intensity Q_c samples back to it with a relative error " << r.noise_relative_error
      << " (above " << kZohInverseMaxError << ")";
    throw ZohInverseError(Part::kNoise, o.str());
  }
  return r;
}

}  // namespace oneshot::design
