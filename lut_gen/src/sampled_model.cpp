/// @file sampled_model.cpp
/// @brief The plant and its cost per period (see sampled_model.hpp).
#include "oneshot/design/sampled_model.hpp"

#include <cmath>
#include <complex>
#include <sstream>

#include "oneshot/design/dense_ops.hpp"
#include "oneshot/design/spectrum.hpp"

namespace oneshot::design {
namespace {

/// B_w W B_wᵀ, symmetrised.
DenseMatrix through(const DenseMatrix& bw, const DenseMatrix& w) {
  DenseMatrix m = bw * w * transpose(bw);
  symmetrize(m);
  return m;
}

/// Φ, Γ over t seconds from one exponential of [[A, B], [0, 0]]·t (seconds, not mirrored).
DenseMatrix zoh_input(const DenseMatrix& a, const DenseMatrix& b, double t) {
  const std::size_t n = a.rows;
  const std::size_t m = b.cols;
  DenseMatrix blk = DenseMatrix::zeros(n + m, n + m);
  set_block(blk, 0, 0, a * t);
  set_block(blk, 0, n, b * t);
  return block(expm(blk, "design: disturbance input over h"), 0, n, n, m);
}

SampledModel sample_continuous(const PlantDescription& p) {
  SampledModel s;
  const std::size_t n = p.n();
  const std::size_t m = p.m();
  const double h = static_cast<double>(p.period_us) * 1e-6;
  // Q_c: the intensity, or Qn/h for a per-period covariance (as the original design reads it).
  DenseMatrix qc_process = DenseMatrix::zeros(n, n);
  DenseMatrix q_step = DenseMatrix::zeros(n, n);
  if (p.process_intensity.rows != 0) {
    qc_process = p.process_intensity;
    q_step = p.process_intensity * h;
  } else if (p.process_covariance_per_period.rows != 0) {
    qc_process = p.process_covariance_per_period * (1.0 / h);
    q_step = p.process_covariance_per_period;
  }
  s.qc = qc_process;
  s.q_constant = q_step;
  if (p.q() != 0) {
    const bool intensity = p.disturbance_intensity.rows != 0;
    const DenseMatrix wc = intensity ? p.disturbance_intensity : p.disturbance_covariance_per_period * (1.0 / h);
    const DenseMatrix wh = intensity ? p.disturbance_intensity * h : p.disturbance_covariance_per_period;
    s.qc = s.qc + through(p.b_w, wc);
    s.q_constant = s.q_constant + through(p.b_w, wh);
    s.gamma_w = zoh_input(p.a, p.b_w, h);
  }
  // Φ(h), Γ(h): the core's GenericDiscretizer operations (per-µs model times integer τ).
  const double t = static_cast<double>(p.period_us);
  const DenseMatrix a_t = (p.a * 1e-6) * t;
  DenseMatrix blk = DenseMatrix::zeros(n + m, n + m);
  set_block(blk, 0, 0, a_t);
  set_block(blk, 0, n, (p.b * 1e-6) * t);
  const DenseMatrix e = expm(blk, "design: the matrix exponential of A h");
  s.phi = block(e, 0, 0, n, n);
  s.gamma = block(e, 0, n, n, m);
  // Q_d(h) by Van Loan: exp([[−A, Q_c], [0, Aᵀ]]·t) = [[·, F₁₂], [0, F₂₂]], Q_d = F₂₂ᵀF₁₂.
  DenseMatrix vl = DenseMatrix::zeros(2 * n, 2 * n);
  set_block(vl, 0, 0, -a_t);
  set_block(vl, 0, n, (s.qc * 1e-6) * t);
  set_block(vl, n, n, transpose(a_t));
  const DenseMatrix f = expm(vl, "design: Van Loan exponential for Q_d(h)");
  s.qd = transpose(block(f, n, n, n, n)) * block(f, 0, n, n, n);
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = i + 1; j < n; ++j) s.qd(j, i) = s.qd(i, j);  // upper triangle mirrored, as the core
  return s;
}

SampledModel sample_discrete(const PlantDescription& p) {
  SampledModel s;
  const std::size_t n = p.n();
  s.phi = p.phi;
  s.gamma = p.gamma;
  s.qd = p.process_covariance_per_period.rows != 0 ? p.process_covariance_per_period : DenseMatrix::zeros(n, n);
  if (p.q() != 0) {
    s.qd = s.qd + through(p.b_w, p.disturbance_covariance_per_period);
    s.gamma_w = p.b_w;
  }
  symmetrize(s.qd);
  s.q_constant = s.qd;
  return s;
}

}  // namespace

SampledModel sample_plant(const PlantDescription& plant) {
  return plant.continuous() ? sample_continuous(plant) : sample_discrete(plant);
}

SampledCost sample_cost(const PlantDescription& p) {
  SampledCost c;
  const std::size_t n = p.n();
  const std::size_t m = p.m();
  if (p.cost_form == CostForm::kDiscrete) {
    c.q1 = p.q1;
    c.q12 = DenseMatrix::zeros(n, m);
    c.q2 = p.q2;
    return c;
  }
  if (p.cost_form != CostForm::kContinuous) return c;
  // Van Loan on F = [[A, B], [0, 0]] with W = blkdiag(Q1c, Q2c).
  const double h = static_cast<double>(p.period_us) * 1e-6;
  const std::size_t k = n + m;
  DenseMatrix f = DenseMatrix::zeros(k, k);
  set_block(f, 0, 0, p.a);
  set_block(f, 0, n, p.b);
  DenseMatrix w = DenseMatrix::zeros(k, k);
  set_block(w, 0, 0, p.q1c);
  set_block(w, n, n, p.q2c);
  DenseMatrix vl = DenseMatrix::zeros(2 * k, 2 * k);
  set_block(vl, 0, 0, (-transpose(f)) * h);
  set_block(vl, 0, k, w * h);
  set_block(vl, k, k, f * h);
  const DenseMatrix e = expm(vl, "design: cannot sample the cost");
  DenseMatrix qs = transpose(block(e, k, k, k, k)) * block(e, 0, k, k, k);
  symmetrize(qs);
  c.q1 = block(qs, 0, 0, n, n);
  c.q12 = block(qs, 0, n, n, m);
  c.q2 = block(qs, n, n, m, m);
  return c;
}

namespace {

/// X⁻¹, or std::domain_error naming `what` when X is singular to working precision.
DenseMatrix inverse_of(const DenseMatrix& x, const char* what) {
  const SolveResult r = solve(x, identity(x.rows), 1e-14);
  if (!r.ok) throw std::domain_error(std::string(what) + ": a square root meets a singular matrix");
  return r.x;
}

/// X^{1/2} by the product form of the Denman–Beavers iteration (Higham, Functions of Matrices,
/// eq. 6.17): M₀ = Y₀ = X, M ← (I + (M + M⁻¹)/2)/2, Y ← Y(I + M⁻¹)/2; M → I, Y → X^{1/2}.
/// Stops one iteration after ‖M − I‖₁ ≤ 1e−13 (quadratic convergence: that one is at rounding).
DenseMatrix square_root(const DenseMatrix& x) {
  const DenseMatrix eye = identity(x.rows);
  DenseMatrix m = x;
  DenseMatrix y = x;
  bool last = false;
  for (int k = 0; k < 100; ++k) {
    const DenseMatrix m_inv = inverse_of(m, "logm");
    y = (y * (eye + m_inv)) * 0.5;
    m = (eye + (m + m_inv) * 0.5) * 0.5;
    if (last) return y;
    last = norm1(m - eye) <= 1e-13;
  }
  throw std::domain_error("logm: the Denman-Beavers square root did not converge in 100 iterations");
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

}  // namespace

DenseMatrix logm(const DenseMatrix& m, int* square_roots) {
  if (m.rows != m.cols) throw std::logic_error("logm: not square");
  const DenseMatrix eye = identity(m.rows);
  DenseMatrix x = m;
  int s = 0;
  while (!(norm1(x - eye) < 0.25)) {
    if (++s > 64) throw std::domain_error("logm: X - I does not fall below 1/4 in 64 square roots");
    x = square_root(x);
  }
  // log(I + Y) = Σ_{k ≥ 1} (−1)^{k+1} Yᵏ/k, ‖Y‖₁ < 1/4: 40 terms leave < 4^{−41}/41 (Horner).
  const DenseMatrix y = x - eye;
  constexpr int kTerms = 40;
  DenseMatrix acc = eye * ((kTerms % 2 == 1 ? 1.0 : -1.0) / kTerms);
  for (int k = kTerms - 1; k >= 1; --k) acc = eye * ((k % 2 == 1 ? 1.0 : -1.0) / k) + y * acc;
  if (square_roots != nullptr) *square_roots = s;
  return (y * acc) * std::ldexp(1.0, s);
}

ZohInverse zoh_inverse(const DenseMatrix& phi, const DenseMatrix& gamma, double h_s, const DenseMatrix& qd) {
  using Part = ZohInverseError::Part;
  const std::size_t n = phi.rows;
  const std::size_t m = gamma.cols;
  if (phi.cols != n || gamma.rows != n || !(h_s > 0)) throw std::logic_error("zoh_inverse: bad shapes or period");
  const double scale = std::fmax(1.0, norm1(phi));
  for (const std::complex<double>& lambda : eigenvalues(phi)) {
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
  DenseMatrix aug = DenseMatrix::zeros(n + m, n + m);
  set_block(aug, 0, 0, phi);
  set_block(aug, 0, n, gamma);
  set_block(aug, n, n, identity(m));
  ZohInverse r;
  DenseMatrix log_m;
  try {
    log_m = logm(aug, &r.square_roots);
  } catch (const std::domain_error& e) {
    throw ZohInverseError(Part::kPhi, e.what());
  }
  // The bottom rows of log M are 0 in exact arithmetic: the continuous model has them 0.
  DenseMatrix f = DenseMatrix::zeros(n + m, n + m);
  set_block(f, 0, 0, block(log_m, 0, 0, n, n + m));
  r.a = block(f, 0, 0, n, n) * (1.0 / h_s);
  r.b = block(f, 0, n, n, m) * (1.0 / h_s);
  set_block(f, 0, 0, r.a * h_s);
  set_block(f, 0, n, r.b * h_s);
  r.relative_error = norm1(expm(f, "d2c: the reconstruction exp([[A, B], [0, 0]] h)") - aug) / norm1(aug);
  if (!(r.relative_error <= kZohInverseMaxError)) {
    std::ostringstream o;
    o << "the continuous plant from the logarithm samples back to it with a relative error " << r.relative_error
      << " (above " << kZohInverseMaxError << "): no accurate continuous equivalent";
    throw ZohInverseError(Part::kPhi, o.str());
  }
  if (qd.rows == 0) return r;
  // Q_d = ∫₀ʰ e^{As} Q_c e^{Aᵀs} ds is linear in Q_c, and regular for the principal A (the
  // eigenvalues λᵢ + λⱼ of L have |Im| < 2π/h): solve it on vec Q_c.
  const std::size_t k = n * n;
  const DenseMatrix map = van_loan_map(r.a, h_s);
  const SolveResult sol = solve(map, DenseMatrix{k, 1, qd.values}, 1e-14);
  if (!sol.ok) throw ZohInverseError(Part::kNoise, "the Van Loan map of the continuous equivalent is singular");
  r.qc = DenseMatrix{n, n, sol.x.values};
  symmetrize(r.qc);
  flush_tiny(r.qc, 1e-14);
  double min_eig = 0;
  for (const std::complex<double>& lambda : eigenvalues(r.qc)) min_eig = std::fmin(min_eig, lambda.real());
  if (min_eig < -1e-10 * max_abs(r.qc)) {
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
  const DenseMatrix back = transpose(block(e, n, n, n, n)) * block(e, 0, n, n, n);
  const double qd_norm = norm1(qd);
  r.noise_relative_error = qd_norm > 0 ? norm1(back - qd) / qd_norm : 0.0;
  if (!(r.noise_relative_error <= kZohInverseMaxError)) {
    std::ostringstream o;
    o << "the continuous intensity Q_c samples back to it with a relative error " << r.noise_relative_error
      << " (above " << kZohInverseMaxError << ")";
    throw ZohInverseError(Part::kNoise, o.str());
  }
  return r;
}

}  // namespace oneshot::design
