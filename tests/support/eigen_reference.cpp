/// @file eigen_reference.cpp
/// @brief The Eigen oracles of eigen_reference.hpp, compiled once for every test target
///        (Eigen's matrix exponential costs each including file seconds of compile time).
#include "support/eigen_reference.hpp"

#include <Eigen/Eigenvalues>
#include <unsupported/Eigen/MatrixFunctions>

namespace oneshot::test {

double relative_error(const MatX& a, const MatX& b) {
  const double scale = b.cwiseAbs().maxCoeff();
  const double err = (a - b).cwiseAbs().maxCoeff();
  return scale > 0 ? err / scale : err;
}

double spectral_radius(const MatX& a) { return Eigen::EigenSolver<MatX>(a).eigenvalues().cwiseAbs().maxCoeff(); }

MatX expm(const MatX& m) { return m.exp(); }

namespace {
using MatL = Eigen::Matrix<long double, Eigen::Dynamic, Eigen::Dynamic>;
MatL to_long(const MatX& m) { return m.cast<long double>(); }
}  // namespace

double dare_residual_long(const MatX& a, const MatX& b, const MatX& q, const MatX& r, const MatX& s, const MatX& x) {
  const MatL al = to_long(a), bl = to_long(b), ql = to_long(q), rl = to_long(r), sl = to_long(s), xl = to_long(x);
  const MatL axa = al.transpose() * xl * al;
  const MatL cross = al.transpose() * xl * bl + sl;
  const MatL corr = cross * (rl + bl.transpose() * xl * bl).inverse() * cross.transpose();
  const MatL res = axa - corr + ql - xl;
  return static_cast<double>(res.norm() / (ql.norm() + axa.norm() + corr.norm()));
}

MatX dare_doubling_long(const MatX& a, const MatX& b, const MatX& q, const MatX& r) {
  MatL al = to_long(a);
  MatL g = to_long(b) * to_long(r).inverse() * to_long(b).transpose();
  MatL h = to_long(q);
  const MatL eye = MatL::Identity(al.rows(), al.cols());
  for (int it = 0; it < 200; ++it) {
    const auto lu = (eye + g * h).partialPivLu();
    const MatL wa = lu.solve(al);
    const MatL wg = lu.solve(g);
    const MatL h_next = h + al.transpose() * h * wa;
    g = g + al * wg * al.transpose();
    al = al * wa;
    const long double change = (h_next - h).cwiseAbs().maxCoeff();
    h = 0.5L * (h_next + h_next.transpose());
    if (change <= 1e-30L * h.cwiseAbs().maxCoeff()) break;
  }
  return h.cast<double>();
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
