/// @file eigen_reference.hpp
/// @brief Oracles written directly from the brief with Eigen (double): the matrix
///        exponential, Van Loan, quadrature of Q_d, the half / complete filters, spectral
///        radii and the Riccati equation in long double. Compiled once (eigen_reference.cpp):
///        Eigen's eigenvalue, exponential and long-double code cost each including test
///        source seconds of compile time.
#pragma once

#include <Eigen/Dense>

#include <cstdint>

#include "oneshot/design/dense_matrix.hpp"
#include "oneshot/matrix.hpp"

namespace oneshot::test {

using MatX = Eigen::MatrixXd;
using VecX = Eigen::VectorXd;

/// DenseMatrix → Eigen.
inline MatX to_eigen(const design::DenseMatrix& d) {
  MatX m(static_cast<Eigen::Index>(d.rows), static_cast<Eigen::Index>(d.cols));
  for (std::size_t i = 0; i < d.rows; ++i)
    for (std::size_t j = 0; j < d.cols; ++j) m(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j)) = d(i, j);
  return m;
}

/// Core matrix (any scalar convertible to double) → Eigen.
template <typename S, std::size_t R, std::size_t C>
MatX to_eigen(const Matrix<S, R, C>& a) {
  MatX m(static_cast<Eigen::Index>(R), static_cast<Eigen::Index>(C));
  for (std::size_t i = 0; i < R; ++i)
    for (std::size_t j = 0; j < C; ++j)
      m(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j)) = ScalarTraits<S>::to_double(a(i, j));
  return m;
}

/// Largest |a − b| / max(|b|) (0 when b is zero and a equals it).
double relative_error(const MatX& a, const MatX& b);

/// max |λ_i(a)| by Eigen's EigenSolver (a square).
double spectral_radius(const MatX& a);

/// e^m by Eigen's MatrixFunctions (m square).
MatX expm(const MatX& m);

/// Relative residual of the discrete Riccati equation with cross weight S, evaluated in long
/// double: R(X) = AᵀXA − (AᵀXB + S)(R + BᵀXB)⁻¹(BᵀXA + Sᵀ) + Q − X, returned as
/// ‖R(X)‖ / (‖Q‖ + ‖AᵀXA‖ + ‖correction‖) (Frobenius norms). The filter's prior Riccati
/// equation is the case A = Φᵀ, B = Cᵀ, S = 0.
double dare_residual_long(const MatX& a, const MatX& b, const MatX& q, const MatX& r, const MatX& s, const MatX& x);

/// The stabilizing solution of X = AᵀX(I + GX)⁻¹A + Q, G = BR⁻¹Bᵀ, by structure-preserving
/// doubling in long double (an oracle independent of the QZ method under test).
MatX dare_doubling_long(const MatX& a, const MatX& b, const MatX& q, const MatX& r);

/// Φ(t), Γ(t), Q_d(t).
struct Triple {
  MatX phi;    ///< Φ(t) = e^{At}.
  MatX gamma;  ///< Γ(t) = ∫₀ᵗ e^{As} ds B.
  MatX qd;     ///< Q_d(t) = ∫₀ᵗ e^{As} Q_c e^{Aᵀs} ds.
};

/// Eigen's matrix exponential of the block matrix (Φ, Γ) and of Van Loan's (Q_d); t in s.
Triple reference_triple(const MatX& a, const MatX& b, const MatX& qc, double t);

/// Q_d(t) = ∫₀ᵗ e^{As} Q_c e^{Aᵀs} ds by composite 5-point Gauss–Legendre (independent of Van Loan).
MatX qd_by_quadrature(const MatX& a, const MatX& qc, double t, int panels = 200);

/// The brief's filters, equation by equation, in double with Eigen.
class ReferenceKalman {
 public:
  /// Plant (A, B, C continuous), Q_c, R, constant Q, h (µs), exact or constant Q.
  ReferenceKalman(MatX a, MatX b, MatX c, MatX qc, MatX r, MatX q_constant, std::int32_t h_us, bool exact)
      : a_(std::move(a)), b_(std::move(b)), c_(std::move(c)), qc_(std::move(qc)), r_(std::move(r)),
        q_(std::move(q_constant)), h_us_(h_us), exact_(exact) {}

  /// Initial estimate at an actuation instant.
  void reset(const VecX& x0, const MatX& p0, const VecX& u0) {
    x_ = x0;
    xs_ = x0;
    p_ = p0;
    u_ = u0;
    u_before_ = u0;
    tau_prev_us_ = 0;
    first_complete_ = true;
  }

  /// Half Kalman job (brief §5).
  void half(std::int32_t tau_us, const VecX& y);

  /// Complete Kalman job (brief §5).
  void complete(std::int32_t tau_us, const VecX& y);

  /// The input applied at the actuation instant just predicted to.
  void set_applied_input(const VecX& u) {
    u_before_ = u_;
    u_ = u;
  }
  const VecX& prediction() const { return x_; }  ///< Estimate at the actuation instant.
  const MatX& covariance() const { return p_; }  ///< P (half: P⁻_k; complete: P_s,k).
  const MatX& gain() const { return k_; }        ///< Last gain.

 private:
  Triple triple(std::int32_t t_us) const;
  void predict(std::int32_t t_us);
  void correct(const VecX& y);

  MatX a_, b_, c_, qc_, r_, q_;
  std::int32_t h_us_;
  bool exact_;
  VecX x_, xs_, u_, u_before_;
  MatX p_, k_;
  std::int32_t tau_prev_us_ = 0;
  bool first_complete_ = true;
};

}  // namespace oneshot::test
