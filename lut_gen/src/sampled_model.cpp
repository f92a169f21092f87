/// @file sampled_model.cpp
/// @brief The plant and its cost per period (see sampled_model.hpp).
#include "oneshot/design/sampled_model.hpp"

#include "oneshot/design/dense_ops.hpp"

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

}  // namespace oneshot::design
