/// @file controller_synthesis.cpp
/// @brief The design step (see controller_synthesis.hpp for the equations).
#include "oneshot/design/controller_synthesis.hpp"

#include <cmath>

#include "oneshot/design/dimension_dispatch.hpp"
#include "oneshot/design/fixed_size.hpp"
#include "oneshot/design/riccati.hpp"
#include "oneshot/generic_discretizer.hpp"
#include "oneshot/linear_solve.hpp"
#include "oneshot/matrix_exponential.hpp"

namespace oneshot::design {
namespace {

using F64 = UniformFormat<double>;

template <std::size_t N>
void symmetrize(Matrix<double, N, N>& m) {
  for (std::size_t i = 0; i < N; ++i)
    for (std::size_t j = i + 1; j < N; ++j) m(i, j) = m(j, i) = 0.5 * (m(i, j) + m(j, i));
}

template <std::size_t N, std::size_t M, std::size_t P>
DesignResult synthesize_fixed(const PlantDescription& plant) {
  DesignResult out;
  const double h = static_cast<double>(plant.period_us) * 1e-6;
  out.period_s = h;
  const auto a = to_fixed<double, N, N>(plant.a);
  const auto b = to_fixed<double, N, M>(plant.b);
  const auto c = to_fixed<double, P, N>(plant.c);
  const auto qn = to_fixed<double, N, N>(plant.process_covariance);
  const auto r = to_fixed<double, P, P>(plant.measurement_covariance);

  // Q_c = Qn / h; Φ(h), Γ(h), Q_d(h) by the generic routine.
  out.qc = to_dense(qn * (1.0 / h));
  const GenericDiscretizer<F64, N, M> generic(continuous_model_per_us<double, N, M>(plant, out));
  Discretization<F64, N, M> dh;
  if (generic.discretize(plant.period_us, dh, WithQd::kYes) != Status::kOk) {
    throw DesignError("design: the matrix exponential of A·h cannot be evaluated (‖A‖·h too large)");
  }
  const Matrix<double, N, N> phi = dh.phi;
  const Matrix<double, N, M> gamma = dh.gamma;
  out.phi_h = to_dense(phi);
  out.gamma_h = to_dense(gamma);
  out.qd_h = to_dense(dh.qd);

  // Sampled cost by Van Loan on F = [[A, B], [0, 0]].
  constexpr std::size_t K = N + M;
  Matrix<double, K, K> f;
  f.template set_block<0, 0>(a);
  f.template set_block<0, N>(b);
  Matrix<double, K, K> w;
  w.template set_block<0, 0>(to_fixed<double, N, N>(plant.q1c));
  w.template set_block<N, N>(to_fixed<double, M, M>(plant.q2c));
  Matrix<double, 2 * K, 2 * K> vl;
  vl.template set_block<0, 0>(-(f.transposed()) * h);
  vl.template set_block<0, K>(w * h);
  vl.template set_block<K, K>(f * h);
  Matrix<double, 2 * K, 2 * K> e;
  if (matrix_exponential(vl, e) != Status::kOk) throw DesignError("design: cannot sample the cost (exponential)");
  Matrix<double, K, K> qs = e.template block<K, K, K, K>().transposed() * e.template block<0, K, K, K>();
  symmetrize(qs);
  const Matrix<double, N, N> q1 = qs.template block<0, 0, N, N>();
  const Matrix<double, N, M> q12 = qs.template block<0, N, N, M>();
  const Matrix<double, M, M> q2 = qs.template block<N, N, M, M>();
  out.q1 = to_dense(q1);
  out.q12 = to_dense(q12);
  out.q2 = to_dense(q2);

  // LQR with cross term.
  Matrix<double, M, M> q2_inv;
  if (invert(q2, q2_inv) != Status::kOk) throw DesignError("design: sampled input weight Q2 is singular");
  const Matrix<double, N, N> a_tilde = phi - gamma * q2_inv * q12.transposed();
  Matrix<double, N, N> q1_tilde = q1 - q12 * q2_inv * q12.transposed();
  symmetrize(q1_tilde);
  Matrix<double, N, N> g = gamma * q2_inv * gamma.transposed();
  symmetrize(g);
  Matrix<double, N, N> s;
  const Status lqr = solve_dare(a_tilde, g, q1_tilde, s);
  if (lqr != Status::kOk) {
    throw DesignError(std::string("design: LQR Riccati equation failed (") + to_string(lqr) +
                      "): is (A, B) stabilisable?");
  }
  const Matrix<double, M, M> lhs = q2 + gamma.transposed() * s * gamma;
  const Matrix<double, M, N> rhs = gamma.transposed() * s * phi + q12.transposed();
  Matrix<double, M, N> l;
  if (solve(lhs, rhs, l) != Status::kOk) throw DesignError("design: LQR gain equation is singular");
  out.riccati = to_dense(s);
  out.l = to_dense(l);
  out.closed_loop_radius = spectral_radius(Matrix<double, N, N>(phi - gamma * l));
  if (!(out.closed_loop_radius < 1.0)) {
    throw DesignError("design: the LQR closed loop is not stable (spectral radius " +
                      std::to_string(out.closed_loop_radius) + ")");
  }

  // Steady-state Kalman filter (dual DARE) with Q_d(h).
  Matrix<double, P, P> r_inv;
  if (invert(r, r_inv) != Status::kOk) throw DesignError("design: R is singular");
  Matrix<double, N, N> gk = c.transposed() * r_inv * c;
  symmetrize(gk);
  Matrix<double, N, N> prior;
  const Status kal = solve_dare(Matrix<double, N, N>(phi.transposed()), gk, dh.qd, prior);
  if (kal != Status::kOk) {
    throw DesignError(std::string("design: Kalman Riccati equation failed (") + to_string(kal) +
                      "): is (A, C) detectable?");
  }
  symmetrize(prior);
  const Matrix<double, P, P> sk = c * prior * c.transposed() + r;
  Matrix<double, P, N> kt;
  if (solve(sk, Matrix<double, P, N>(c * prior), kt) != Status::kOk) {
    throw DesignError("design: innovation covariance is singular");
  }
  const Matrix<double, N, P> k = kt.transposed();
  Matrix<double, N, N> posterior = (Matrix<double, N, N>::identity() - k * c) * prior;
  symmetrize(posterior);
  out.kalman_prior = to_dense(prior);
  out.kalman_posterior = to_dense(posterior);
  out.kalman_gain = to_dense(k);
  out.estimator_radius = spectral_radius(Matrix<double, N, N>((Matrix<double, N, N>::identity() - k * c) * phi));

  // Set-point feed-forward.
  out.nx = DenseMatrix::zeros(N, P);
  out.nu = DenseMatrix::zeros(M, P);
  if constexpr (P == M) {
    Matrix<double, N + M, N + M> sys;
    sys.template set_block<0, 0>(a);
    sys.template set_block<0, N>(b);
    sys.template set_block<N, 0>(c);
    Matrix<double, N + M, P> rhs_ff;
    for (std::size_t i = 0; i < P; ++i) rhs_ff(N + i, i) = 1.0;
    Matrix<double, N + M, P> sol;
    if (solve(sys, rhs_ff, sol) == Status::kOk) {
      out.tracking = true;
      out.nx = to_dense(Matrix<double, N, P>(sol.template block<0, 0, N, P>()));
      out.nu = to_dense(Matrix<double, M, P>(sol.template block<N, 0, M, P>()));
      for (double& v : out.nx.values) v = std::fabs(v) < 1e-14 ? 0.0 : v;  // exact zeros, not −0/rounding
      for (double& v : out.nu.values) v = std::fabs(v) < 1e-14 ? 0.0 : v;
    }
  }

  // Current deadbeat observer (single output).
  out.deadbeat_gain = DenseMatrix::zeros(N, P);
  if constexpr (P == 1) {
    Matrix<double, N, N> obs;
    Matrix<double, N, N> phi_pow = phi;  // Φ^k
    for (std::size_t i = 0; i < N; ++i) {
      const Matrix<double, 1, N> row = c * phi_pow;
      for (std::size_t j = 0; j < N; ++j) obs(i, j) = row(0, j);
      if (i + 1 < N) phi_pow = phi_pow * phi;
    }
    // phi_pow = Φⁿ now.
    Vector<double, N> en;
    en[N - 1] = 1.0;
    Vector<double, N> o_inv_en;
    if (solve(obs, en, o_inv_en) == Status::kOk) {
      out.deadbeat = true;
      out.deadbeat_gain = to_dense(Matrix<double, N, 1>(phi_pow * o_inv_en));
    }
  }

  out.p0 = plant.has_initial_covariance ? plant.initial_covariance : out.kalman_prior;
  out.q_constant = plant.process_covariance;
  out.r = plant.measurement_covariance;

  const BoardDescription& bd = plant.board;
  for (std::size_t j = 0; j < M; ++j) {
    const double span = bd.pwm_high_volts[j] - bd.pwm_low_volts[j];
    out.u_min.push_back(bd.pwm_low_volts[j]);
    out.volts_per_step.push_back(span / bd.pwm_duty_steps);
    out.steps_per_volt.push_back(bd.pwm_duty_steps / span);
  }
  out.actuator_steps = bd.pwm_duty_steps;
  for (std::size_t o = 0; o < P; ++o) {
    const double lsb = (bd.adc_max_volts[o] - bd.adc_min_volts[o]) / std::ldexp(1.0, bd.adc_bits);
    out.volts_per_code.push_back(lsb);
    out.y_offset.push_back(bd.adc_min_volts[o] + 0.5 * lsb);
  }
  return out;
}

}  // namespace

DesignResult synthesize(const PlantDescription& plant) {
  return with_dimensions(plant.n(), plant.m(), plant.p(), [&](auto n, auto m, auto p) {
    return synthesize_fixed<decltype(n)::value, decltype(m)::value, decltype(p)::value>(plant);
  });
}

}  // namespace oneshot::design
