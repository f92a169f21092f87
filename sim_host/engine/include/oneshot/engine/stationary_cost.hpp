/// @file stationary_cost.hpp
/// @brief Stationary expected cost per unit time of a jump-linear loop whose timing is drawn
///        i.i.d. per period from a finite set of cases (the Jitterbug method).
///
/// A period of timing case i (probability p_i, length T_i) maps the covariance Σ of the
/// closed-loop state z at its start (mean zero, reference zero: the noise-driven part of the
/// cost) to
///     Σ' = 𝓔_i(Σ) + W_i,                  cost_i(Σ) = ⟨Q_i, Σ⟩ + c_i,
/// both affine in Σ (flows and jumps of JumpLinearCost are). With the case drawn independently
/// each period, the stationary covariance solves the linear equations
///     Σ = Σ_i p_i (𝓔_i(Σ) + W_i)
/// on the K(K+1)/2 entries of the symmetric Σ, and the cost per unit time is
///     J = Σ_i p_i cost_i(Σ) / Σ_i p_i T_i      (renewal–reward).
/// The caller runs one period of case i from a given Σ on its own JumpLinearCost (the engine
/// knows no study); stationary_cost() probes each case with Σ = 0 and with every element of
/// the symmetric basis (e_a e_bᵀ + e_b e_aᵀ), assembles 𝒜 = Σ p_i 𝓔_i, and solves
/// (I − 𝒜) vech Σ = Σ p_i vech W_i by LAPACK. The loop is mean-square stable iff the spectral
/// radius of 𝒜 is below 1; otherwise the cost is infinite and the call throws, naming it.
/// A register of z that a loop never writes nor reads (a spare slot of a shared layout) keeps
/// its covariance for ever (an eigenvalue 1 of 𝒜 that does not move the cost): the caller names
/// the live entries, the others are held at zero, and each dead entry is probed in every case to
/// check that it indeed moves neither a live entry nor the cost (std::logic_error otherwise).
#pragma once

#include <cstddef>
#include <stdexcept>
#include <string>
#include <vector>

#include "oneshot/design/dense_matrix.hpp"
#include "oneshot/matrix.hpp"

namespace oneshot::engine {

/// What one period of a timing case gives from a start covariance: the end covariance and the
/// expected cost of the period (covariance and noise-path parts of ExpectedCost).
template <std::size_t K>
struct PeriodOutcome {
  Matrix<double, K, K> sigma;  ///< Σ at the period's end.
  double cost = 0;             ///< E[∫ cost] over the period (mean-zero part).
};

/// The stationary solution.
struct StationaryCost {
  double cost_rate = 0;          ///< J per second: E[cost of a period] / E[period length].
  double cost_per_period = 0;    ///< E[cost of a period] at the stationary Σ.
  double mean_period_s = 0;      ///< E[T_i] (s).
  double spectral_radius = 0;    ///< ρ(𝒜): below 1 (mean-square stable) or the call throws.
  double residual = 0;           ///< max |Σ − Σ_i p_i (𝓔_i(Σ) + W_i)| / max |Σ| at the solution.
  design::DenseMatrix sigma;     ///< Stationary Σ at a period start (K×K, zero on dead entries).
};

/// The linear algebra of stationary_cost() on k live entries: `ops` (n×n, n = k(k+1)/2) is 𝒜 in vech coordinates,
/// `w` (n) Σ p_i vech W_i, `q` (n) the cost functional on the basis and `c` Σ p_i c_i; std::domain_error
/// when ρ(𝒜) ≥ 1 or the system is singular.
StationaryCost solve_stationary(std::size_t k, const design::DenseMatrix& ops, const std::vector<double>& w,
                                const std::vector<double>& q, double c, double mean_period_s);

/// The stationary cost of the cases with probabilities `p` (summing to 1 within 1e-9) and
/// lengths `period_s`; `run(i, Σ)` returns the PeriodOutcome of case i from Σ (mean zero);
/// `live` (empty: all) marks the entries of z the loop uses.
template <std::size_t K, typename Run>
StationaryCost stationary_cost(const std::vector<double>& p, const std::vector<double>& period_s, Run&& run,
                               std::vector<bool> live = {}) {
  if (p.empty() || p.size() != period_s.size()) throw std::invalid_argument("stationary_cost: one probability and one length per case");
  if (live.empty()) live.assign(K, true);
  if (live.size() != K) throw std::invalid_argument("stationary_cost: the live mask needs one flag per entry of z");
  std::vector<std::size_t> idx;  // live entries
  for (std::size_t a = 0; a < K; ++a)
    if (live[a]) idx.push_back(a);
  const std::size_t k = idx.size();
  const std::size_t n = k * (k + 1) / 2;
  design::DenseMatrix ops = design::DenseMatrix::zeros(n, n);
  std::vector<double> w(n, 0.0);
  std::vector<double> q(n, 0.0);
  double c = 0;
  double total = 0;
  double mean_period = 0;
  // vech of the live block of an outcome's Σ minus the base's, weighted by p.
  const auto add_column = [&](double pi, const Matrix<double, K, K>& s, const Matrix<double, K, K>& base, std::size_t col) {
    std::size_t row = 0;
    for (std::size_t r = 0; r < k; ++r)
      for (std::size_t t = r; t < k; ++t, ++row) ops(row, col) += pi * (s(idx[r], idx[t]) - base(idx[r], idx[t]));
  };
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (!(p[i] >= 0) || !(period_s[i] > 0)) throw std::invalid_argument("stationary_cost: case " + std::to_string(i) + " has p < 0 or length <= 0");
    total += p[i];
    mean_period += p[i] * period_s[i];
    if (p[i] == 0) continue;
    const PeriodOutcome<K> base = run(i, Matrix<double, K, K>{});
    c += p[i] * base.cost;
    std::size_t col = 0;
    for (std::size_t a = 0; a < k; ++a) {
      for (std::size_t b = a; b < k; ++b, ++col) {
        Matrix<double, K, K> basis{};
        basis(idx[a], idx[b]) = 1;
        basis(idx[b], idx[a]) = 1;
        const PeriodOutcome<K> o = run(i, basis);
        q[col] += p[i] * (o.cost - base.cost);
        add_column(p[i], o.sigma, base.sigma, col);
      }
    }
    std::size_t row = 0;
    for (std::size_t r = 0; r < k; ++r)
      for (std::size_t t = r; t < k; ++t, ++row) w[row] += p[i] * base.sigma(idx[r], idx[t]);
    for (std::size_t a = 0; a < K; ++a) {  // every case: a register dead in one may be read in another
      if (live[a]) continue;
      Matrix<double, K, K> basis{};
      basis(a, a) = 1;
      const PeriodOutcome<K> o = run(i, basis);
      bool moved = o.cost != base.cost;
      for (std::size_t r : idx)
        for (std::size_t t : idx) moved = moved || o.sigma(r, t) != base.sigma(r, t);
      if (moved) throw std::logic_error("stationary_cost: entry " + std::to_string(a) + " of z is declared dead but moves the loop");
    }
  }
  if (!(total > 1 - 1e-9 && total < 1 + 1e-9)) throw std::invalid_argument("stationary_cost: probabilities sum to " + std::to_string(total) + ", not 1");
  StationaryCost r = solve_stationary(k, ops, w, q, c, mean_period);
  design::DenseMatrix full = design::DenseMatrix::zeros(K, K);
  for (std::size_t a = 0; a < k; ++a)
    for (std::size_t b = 0; b < k; ++b) full(idx[a], idx[b]) = r.sigma(a, b);
  r.sigma = full;
  return r;
}

}  // namespace oneshot::engine
