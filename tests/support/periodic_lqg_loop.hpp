/// @file periodic_lqg_loop.hpp
/// @brief Test fixture: a lightly damped oscillator under periodic LQG control (LQ gain of the
///        exactly sampled cost, stationary Kalman filter, both by Riccati iteration in Eigen),
///        its sampling event as a JumpLinearCost map, and the quadratures its oracles need.
///        Used by the JumpLinearCost and stationary-cost tests.
#pragma once

#include <cstddef>

#include "oneshot/engine/jump_linear_cost.hpp"
#include "support/eigen_reference.hpp"

namespace oneshot::engine::lqg_fixture {

using test::MatX;
using test::VecX;
constexpr std::size_t kN = 2;
constexpr std::size_t kM = 1;
constexpr std::size_t kK = 5;  // z = [x (2); u (1); x̂⁻ (2)]
using Jlc = JumpLinearCost<kN, kM, kK>;

/// Lightly damped oscillator, position measured; cost Q1c = I, Q2c = 0.1.
struct Loop {
  MatX a = (MatX(2, 2) << 0, 1, -4, -0.4).finished();
  MatX b = (MatX(2, 1) << 0, 1).finished();
  MatX c = (MatX(1, 2) << 1, 0).finished();
  MatX qc = (MatX(2, 2) << 0.01, 0, 0, 0.04).finished();
  MatX q1c = MatX::Identity(2, 2);
  double q2c = 0.1;
  double r = 0.02;  // measurement variance
  double h = 0.1;
  MatX phi, gamma, qd, l, k, s, pf;
  MatX gc;  // sampled cost weight of [x; u] over h
};

/// ∫₀^t [Φ(s) Γ(s)]ᵀ Q1c [Φ(s) Γ(s)] ds + blkdiag(0, Q2c t) by composite Gauss–Legendre.
inline MatX sampled_cost(const Loop& p, double t) {
  static const double x[5] = {-0.9061798459386640, -0.5384693101056831, 0.0, 0.5384693101056831, 0.9061798459386640};
  static const double w[5] = {0.2369268850561891, 0.4786286704993665, 0.5688888888888889, 0.4786286704993665,
                              0.2369268850561891};
  MatX g = MatX::Zero(3, 3);
  const int panels = 40;
  const double hp = t / panels;
  for (int q = 0; q < panels; ++q)
    for (int i = 0; i < 5; ++i) {
      const double sv = hp * (q + 0.5 + 0.5 * x[i]);
      const test::Triple tr = test::reference_triple(p.a, p.b, p.qc, sv);
      MatX m(2, 3);
      m << tr.phi, tr.gamma;
      g += 0.5 * hp * w[i] * m.transpose() * p.q1c * m;
    }
  g(2, 2) += p.q2c * t;
  return g;
}

/// ∫₀^t tr(Q1c Q_d(s)) ds by composite Gauss–Legendre (Q_d by Eigen's Van Loan).
inline double noise_path(const Loop& p, double t) {
  static const double x[5] = {-0.9061798459386640, -0.5384693101056831, 0.0, 0.5384693101056831, 0.9061798459386640};
  static const double w[5] = {0.2369268850561891, 0.4786286704993665, 0.5688888888888889, 0.4786286704993665,
                              0.2369268850561891};
  double sum = 0;
  const int panels = 40;
  const double hp = t / panels;
  for (int q = 0; q < panels; ++q)
    for (int i = 0; i < 5; ++i) {
      const double sv = hp * (q + 0.5 + 0.5 * x[i]);
      sum += 0.5 * hp * w[i] * (p.q1c * test::reference_triple(p.a, p.b, p.qc, sv).qd).trace();
    }
  return sum;
}

/// LQ gain of the sampled cost (DARE with cross term) and the stationary Kalman gain, by iteration.
inline Loop designed() {
  Loop p;
  const test::Triple tr = test::reference_triple(p.a, p.b, p.qc, p.h);
  p.phi = tr.phi;
  p.gamma = tr.gamma;
  p.qd = tr.qd;
  p.gc = sampled_cost(p, p.h);
  const MatX q1 = p.gc.topLeftCorner(2, 2);
  const MatX q12 = p.gc.topRightCorner(2, 1);
  const MatX q2 = p.gc.bottomRightCorner(1, 1);
  MatX s = q1;
  for (int i = 0; i < 20000; ++i) {
    const MatX w = q2 + p.gamma.transpose() * s * p.gamma;
    const MatX l = w.inverse() * (p.gamma.transpose() * s * p.phi + q12.transpose());
    const MatX next = q1 + p.phi.transpose() * s * p.phi - (p.phi.transpose() * s * p.gamma + q12) * l;
    const double change = (next - s).cwiseAbs().maxCoeff();
    s = 0.5 * (next + next.transpose());
    if (change < 1e-15 * s.cwiseAbs().maxCoeff()) break;
  }
  p.s = s;
  p.l = (q2 + p.gamma.transpose() * s * p.gamma).inverse() * (p.gamma.transpose() * s * p.phi + q12.transpose());
  MatX pm = p.qd;
  for (int i = 0; i < 20000; ++i) {
    const double inn = (p.c * pm * p.c.transpose())(0, 0) + p.r;
    const MatX f = pm - pm * p.c.transpose() * p.c * pm / inn;
    const MatX next = p.phi * f * p.phi.transpose() + p.qd;
    const double change = (next - pm).cwiseAbs().maxCoeff();
    pm = 0.5 * (next + next.transpose());
    if (change < 1e-17) break;
  }
  const double inn = (p.c * pm * p.c.transpose())(0, 0) + p.r;
  p.k = pm * p.c.transpose() / inn;
  p.pf = pm - pm * p.c.transpose() * p.c * pm / inn;
  return p;
}

/// The event at a sampling instant: y = C x + v, x̂ = x̂⁻ + K (y − C x̂⁻), u = u_ref − L (x̂ − x_ref),
/// x̂⁻ ← Φ(h) x̂ + Γ(h) u, as z⁺ = E z + F v + g.
struct EventMap {
  Jlc::Map e = Jlc::Map::identity();
  Matrix<double, kK, 1> f;
  Jlc::Z g;
};
inline EventMap event_map(const Loop& p, double x_ref, double u_ref) {
  const MatX ikc = MatX::Identity(2, 2) - p.k * p.c;
  const MatX kc = p.k * p.c;
  const MatX acl = p.phi - p.gamma * p.l;
  const double gu = u_ref + (p.l * VecX((VecX(2) << x_ref, 0).finished()))(0);
  EventMap m;
  for (std::size_t j = 0; j < 5; ++j) m.e(2, j) = 0;
  for (int j = 0; j < 2; ++j) {
    m.e(2, static_cast<std::size_t>(j)) = -(p.l * kc)(0, j);
    m.e(2, 3 + static_cast<std::size_t>(j)) = -(p.l * ikc)(0, j);
  }
  for (int i = 0; i < 2; ++i) {
    const auto zi = 3 + static_cast<std::size_t>(i);
    for (std::size_t j = 0; j < 5; ++j) m.e(zi, j) = 0;
    for (int j = 0; j < 2; ++j) {
      m.e(zi, static_cast<std::size_t>(j)) = (acl * kc)(i, j);
      m.e(zi, 3 + static_cast<std::size_t>(j)) = (acl * ikc)(i, j);
    }
    m.f(zi, 0) = (acl * p.k)(i, 0);
    m.g[zi] = p.gamma(i, 0) * gu;
  }
  m.f(2, 0) = -(p.l * p.k)(0, 0);
  m.g[2] = gu;
  return m;
}

inline JumpLinearPlant<kN, kM> engine_plant(const Loop& p, bool noisy) {
  JumpLinearPlant<kN, kM> e;
  for (std::size_t i = 0; i < 2; ++i) {
    for (std::size_t j = 0; j < 2; ++j) {
      const auto ii = static_cast<Eigen::Index>(i);
      const auto jj = static_cast<Eigen::Index>(j);
      e.a(i, j) = p.a(ii, jj);
      e.qc(i, j) = noisy ? p.qc(ii, jj) : 0;
      e.q1c(i, j) = p.q1c(ii, jj);
    }
    e.b(i, 0) = p.b(static_cast<Eigen::Index>(i), 0);
  }
  e.q2c(0, 0) = p.q2c;
  return e;
}

/// The designed loop, its noisy JumpLinearCost, its sampling event at reference zero and R.
struct LqgSetup {
  Loop p = designed();                   ///< Plant, gains, closed forms.
  Jlc jl{engine_plant(p, true)};         ///< Propagation with process noise.
  EventMap m = event_map(p, 0, 0);       ///< Sampling event, reference zero.
  Matrix<double, 1, 1> r;                ///< Measurement variance.
  LqgSetup() { r(0, 0) = p.r; }
};

}  // namespace oneshot::engine::lqg_fixture
