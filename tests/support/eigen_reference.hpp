/// @file eigen_reference.hpp
/// @brief Oracles written directly from the brief with Eigen (double): the matrix
///        exponential, Van Loan, quadrature of Q_d, and the half / complete filters.
#pragma once

#include <Eigen/Dense>
#include <unsupported/Eigen/MatrixFunctions>

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
inline double relative_error(const MatX& a, const MatX& b) {
  const double scale = b.cwiseAbs().maxCoeff();
  const double err = (a - b).cwiseAbs().maxCoeff();
  return scale > 0 ? err / scale : err;
}

/// Φ(t), Γ(t), Q_d(t).
struct Triple {
  MatX phi;
  MatX gamma;
  MatX qd;
};

/// Eigen's matrix exponential of the block matrix (Φ, Γ) and of Van Loan's (Q_d); t in s.
inline Triple reference_triple(const MatX& a, const MatX& b, const MatX& qc, double t) {
  const Eigen::Index n = a.rows();
  const Eigen::Index m = b.cols();
  MatX block = MatX::Zero(n + m, n + m);
  block.topLeftCorner(n, n) = a * t;
  block.topRightCorner(n, m) = b * t;
  const MatX e = block.exp();
  MatX vl = MatX::Zero(2 * n, 2 * n);
  vl.topLeftCorner(n, n) = -a * t;
  vl.topRightCorner(n, n) = qc * t;
  vl.bottomRightCorner(n, n) = a.transpose() * t;
  const MatX f = vl.exp();
  Triple tr;
  tr.phi = e.topLeftCorner(n, n);
  tr.gamma = e.topRightCorner(n, m);
  tr.qd = f.bottomRightCorner(n, n).transpose() * f.topRightCorner(n, n);
  return tr;
}

/// Q_d(t) = ∫₀ᵗ e^{As} Q_c e^{Aᵀs} ds by composite 5-point Gauss–Legendre (independent of Van Loan).
inline MatX qd_by_quadrature(const MatX& a, const MatX& qc, double t, int panels = 200) {
  static const double x[5] = {-0.9061798459386640, -0.5384693101056831, 0.0, 0.5384693101056831,
                              0.9061798459386640};
  static const double w[5] = {0.2369268850561891, 0.4786286704993665, 0.5688888888888889, 0.4786286704993665,
                              0.2369268850561891};
  MatX sum = MatX::Zero(a.rows(), a.cols());
  const double hp = t / panels;
  for (int p = 0; p < panels; ++p)
    for (int k = 0; k < 5; ++k) {
      const double s = hp * (p + 0.5 + 0.5 * x[k]);
      const MatX e = (a * s).exp();
      sum += 0.5 * hp * w[k] * e * qc * e.transpose();
    }
  return sum;
}

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
  void half(std::int32_t tau_us, const VecX& y) {
    predict(h_us_ - tau_us);
    correct(y);
    predict(tau_us);
  }

  /// Complete Kalman job (brief §5).
  void complete(std::int32_t tau_us, const VecX& y) {
    const std::int32_t b_us = h_us_ - tau_us;
    const Triple sum = triple(b_us + tau_prev_us_);
    const Triple tb = triple(b_us);
    const Triple ta = triple(tau_prev_us_);
    x_ = sum.phi * xs_ + tb.phi * ta.gamma * u_before_ + tb.gamma * u_;
    // Constant Q: the interval a of the first job starts at the reset (an actuation instant).
    const MatX q_sum = exact_ ? sum.qd : (first_complete_ ? q_ : MatX(tb.phi * q_ * tb.phi.transpose() + q_));
    p_ = sum.phi * p_ * sum.phi.transpose() + q_sum;
    first_complete_ = false;
    correct(y);
    xs_ = x_;
    const Triple tc = triple(tau_us);
    x_ = tc.phi * xs_ + tc.gamma * u_;
    tau_prev_us_ = tau_us;
  }

  /// The input applied at the actuation instant just predicted to.
  void set_applied_input(const VecX& u) {
    u_before_ = u_;
    u_ = u;
  }
  const VecX& prediction() const { return x_; }  ///< Estimate at the actuation instant.
  const MatX& covariance() const { return p_; }  ///< P (half: P⁻_k; complete: P_s,k).
  const MatX& gain() const { return k_; }        ///< Last gain.

 private:
  Triple triple(std::int32_t t_us) const { return reference_triple(a_, b_, qc_, t_us * 1e-6); }
  void predict(std::int32_t t_us) {
    const Triple t = triple(t_us);
    x_ = t.phi * x_ + t.gamma * u_;
    p_ = t.phi * p_ * t.phi.transpose() + (exact_ ? t.qd : q_);
  }
  void correct(const VecX& y) {
    const MatX s = c_ * p_ * c_.transpose() + r_;
    k_ = p_ * c_.transpose() * s.inverse();
    x_ = x_ + k_ * (y - c_ * x_);
    p_ = (MatX::Identity(p_.rows(), p_.cols()) - k_ * c_) * p_;
  }

  MatX a_, b_, c_, qc_, r_, q_;
  std::int32_t h_us_;
  bool exact_;
  VecX x_, xs_, u_, u_before_;
  MatX p_, k_;
  std::int32_t tau_prev_us_ = 0;
  bool first_complete_ = true;
};

}  // namespace oneshot::test
