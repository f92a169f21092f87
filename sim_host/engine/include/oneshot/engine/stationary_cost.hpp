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
  design::DenseMatrix sigma;     ///< Stationary Σ at a period start (K×K).
};

/// The linear algebra of stationary_cost(): `ops` (n×n, n = K(K+1)/2) is 𝒜 in vech coordinates,
/// `w` (n) Σ p_i vech W_i, `q` (n) the cost functional on the basis and `c` Σ p_i c_i; std::domain_error
/// when ρ(𝒜) ≥ 1 or the system is singular.
StationaryCost solve_stationary(std::size_t k, const design::DenseMatrix& ops, const std::vector<double>& w,
                                const std::vector<double>& q, double c, double mean_period_s);

/// The stationary cost of the cases with probabilities `p` (summing to 1 within 1e-9) and
/// lengths `period_s`; `run(i, Σ)` returns the PeriodOutcome of case i from Σ (mean zero).
template <std::size_t K, typename Run>
StationaryCost stationary_cost(const std::vector<double>& p, const std::vector<double>& period_s, Run&& run) {
  if (p.empty() || p.size() != period_s.size()) throw std::invalid_argument("stationary_cost: one probability and one length per case");
  constexpr std::size_t n = K * (K + 1) / 2;
  design::DenseMatrix ops = design::DenseMatrix::zeros(n, n);
  std::vector<double> w(n, 0.0);
  std::vector<double> q(n, 0.0);
  double c = 0;
  double total = 0;
  double mean_period = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (!(p[i] >= 0) || !(period_s[i] > 0)) throw std::invalid_argument("stationary_cost: case " + std::to_string(i) + " has p < 0 or length <= 0");
    total += p[i];
    mean_period += p[i] * period_s[i];
    if (p[i] == 0) continue;
    const PeriodOutcome<K> base = run(i, Matrix<double, K, K>{});
    c += p[i] * base.cost;
    std::size_t col = 0;
    for (std::size_t a = 0; a < K; ++a) {
      for (std::size_t b = a; b < K; ++b, ++col) {
        Matrix<double, K, K> basis{};
        basis(a, b) = 1;
        basis(b, a) = 1;
        const PeriodOutcome<K> o = run(i, basis);
        q[col] += p[i] * (o.cost - base.cost);
        std::size_t row = 0;
        for (std::size_t r = 0; r < K; ++r)
          for (std::size_t s = r; s < K; ++s, ++row) ops(row, col) += p[i] * (o.sigma(r, s) - base.sigma(r, s));
      }
    }
    std::size_t row = 0;
    for (std::size_t r = 0; r < K; ++r)
      for (std::size_t s = r; s < K; ++s, ++row) w[row] += p[i] * base.sigma(r, s);
  }
  if (!(total > 1 - 1e-9 && total < 1 + 1e-9)) throw std::invalid_argument("stationary_cost: probabilities sum to " + std::to_string(total) + ", not 1");
  return solve_stationary(K, ops, w, q, c, mean_period);
}

}  // namespace oneshot::engine
