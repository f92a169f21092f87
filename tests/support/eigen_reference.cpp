/// @file eigen_reference.cpp
/// @brief The Eigen oracles of eigen_reference.hpp, compiled once for every test target
///        (Eigen's matrix exponential costs each including file seconds of compile time).
#include "support/eigen_reference.hpp"

#include <unsupported/Eigen/MatrixFunctions>

namespace oneshot::test {

double relative_error(const MatX& a, const MatX& b) {
  const double scale = b.cwiseAbs().maxCoeff();
  const double err = (a - b).cwiseAbs().maxCoeff();
  return scale > 0 ? err / scale : err;
}

Triple reference_triple(const MatX& a, const MatX& b, const MatX& qc, double t) {
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

MatX qd_by_quadrature(const MatX& a, const MatX& qc, double t, int panels) {
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

void ReferenceKalman::half(std::int32_t tau_us, const VecX& y) {
    predict(h_us_ - tau_us);
    correct(y);
    predict(tau_us);
  }

void ReferenceKalman::complete(std::int32_t tau_us, const VecX& y) {
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

Triple ReferenceKalman::triple(std::int32_t t_us) const { return reference_triple(a_, b_, qc_, t_us * 1e-6); }

void ReferenceKalman::predict(std::int32_t t_us) {
    const Triple t = triple(t_us);
    x_ = t.phi * x_ + t.gamma * u_;
    p_ = t.phi * p_ * t.phi.transpose() + (exact_ ? t.qd : q_);
  }

void ReferenceKalman::correct(const VecX& y) {
    const MatX s = c_ * p_ * c_.transpose() + r_;
    k_ = p_ * c_.transpose() * s.inverse();
    x_ = x_ + k_ * (y - c_ * x_);
    p_ = (MatX::Identity(p_.rows(), p_.cols()) - k_ * c_) * p_;
  }

}  // namespace oneshot::test
