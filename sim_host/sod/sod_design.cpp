/// @file sod_design.cpp
/// @brief The δt design (see sod_design.hpp).
#include "sod_design.hpp"

#include <cmath>
#include <functional>
#include <limits>
#include <stdexcept>

#include "oneshot/design/dare.hpp"

namespace oneshot::sod {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

/// Σ_k Φ^k Q (Φ^k)ᵀ by doubling (no measurement at all; Φ stable).
std::vector<double> lyapunov_diag(const SodModel& m) {
  double a[2][2], p[2][2];
  for (std::size_t i = 0; i < 2; ++i)
    for (std::size_t j = 0; j < 2; ++j) {
      a[i][j] = m.a_d(i, j);
      p[i][j] = m.q_d(i, j);
    }
  for (int it = 0; it < 200; ++it) {
    double ap[2][2] = {}, apa[2][2] = {}, aa[2][2] = {};
    for (int i = 0; i < 2; ++i)
      for (int j = 0; j < 2; ++j)
        for (int l = 0; l < 2; ++l) {
          ap[i][j] += a[i][l] * p[l][j];
          aa[i][j] += a[i][l] * a[l][j];
        }
    for (int i = 0; i < 2; ++i)
      for (int j = 0; j < 2; ++j)
        for (int l = 0; l < 2; ++l) apa[i][j] += ap[i][l] * a[j][l];
    double change = 0;
    for (int i = 0; i < 2; ++i)
      for (int j = 0; j < 2; ++j) {
        p[i][j] += apa[i][j];
        change = std::max(change, std::abs(apa[i][j]) / std::max(std::abs(p[i][j]), 1e-300));
        a[i][j] = aa[i][j];
      }
    if (change < 1e-16) return {p[0][0], p[1][1]};
  }
  throw std::runtime_error("sod design: the open-loop covariance does not converge (A_d not stable)");
}

}  // namespace

std::vector<double> prior_riccati_diag(const SodModel& model, const double (&delta_y)[kNodes],
                                       const double (&dbar)[kNodes]) {
  std::vector<std::size_t> rows;
  for (std::size_t i = 0; i < kNodes; ++i)
    if (std::isfinite(dbar[i])) rows.push_back(i);
  if (rows.empty()) return lyapunov_diag(model);
  const std::size_t q = rows.size();
  design::DenseMatrix at = design::DenseMatrix::zeros(kStates, kStates);
  design::DenseMatrix ct = design::DenseMatrix::zeros(kStates, q);
  design::DenseMatrix r = design::DenseMatrix::zeros(q, q);
  for (std::size_t i = 0; i < kStates; ++i)
    for (std::size_t j = 0; j < kStates; ++j) at(i, j) = model.phi(j, i);
  for (std::size_t a = 0; a < q; ++a) {
    const std::size_t i = rows[a];
    for (std::size_t j = 0; j < kStates; ++j) ct(j, a) = model.cm(i, j);
    const double w = (dbar[i] + 1) * delta_y[i];
    r(a, a) = model.r_diag[i] + w * w / 3;  // (9)
  }
  const design::DareSolution s = design::solve_dare(at, ct, model.qd, r);  // (10), the dual DARE
  if (s.status != design::DareStatus::kOk) {
    throw std::runtime_error(std::string("sod design: prior DARE failed: ") + design::to_string(s.status));
  }
  return {s.x(0, 0), s.x(1, 1)};
}

DeltaTDesign design_delta_t(const SodModel& model, const DesignInputs& in) {
  if (!(in.mu > 1) || !std::isfinite(in.mu)) throw std::invalid_argument("sod design: mu must be finite and > 1");
  for (std::size_t i = 0; i < kNodes; ++i) {
    if (!(in.loss[i] >= 0 && in.loss[i] < 1)) throw std::invalid_argument("sod design: loss rate must lie in [0, 1)");
    if (!(in.mean_gap_s[i] > 0) || !std::isfinite(in.mean_gap_s[i])) throw std::invalid_argument("sod design: mean gap DeltaT must be finite and > 0");
    if (!(in.delta_y[i] >= 0) || !std::isfinite(in.delta_y[i])) throw std::invalid_argument("sod design: delta_y must be finite and >= 0");
  }
  DeltaTDesign out;
  const double zero[kNodes] = {0, 0};
  const std::vector<double> p0 = prior_riccati_diag(model, in.delta_y, zero);
  out.p0_diag[0] = p0[0];
  out.p0_diag[1] = p0[1];
  out.riccati_solves = 1;
  auto feasible = [&](double d1, double d2) {
    const double d[kNodes] = {d1, d2};
    const std::vector<double> p = prior_riccati_diag(model, in.delta_y, d);
    ++out.riccati_solves;
    return p[0] <= in.mu * p0[0] * (1 + 1e-12) && p[1] <= in.mu * p0[1] * (1 + 1e-12);
  };
  // Largest x with pred(x) (pred(0) holds, pred is monotone): ∞ when pred(∞).
  auto sup = [&](const std::function<bool(double)>& pred) {
    if (pred(kInf)) return kInf;
    double lo = 0, hi = 1;
    while (pred(hi)) {
      lo = hi;
      hi *= 2;
      if (hi > 1e15) throw std::runtime_error("sod design: feasible set unbounded but infinity infeasible");
    }
    while (hi - lo > 1e-9 * hi) {
      const double mid = 0.5 * (lo + hi);
      (pred(mid) ? lo : hi) = mid;
    }
    return lo;
  };
  const double c[kNodes] = {in.loss[0] / in.mean_gap_s[0], in.loss[1] / in.mean_gap_s[1]};  // 1/δt = c/d̄
  auto rate = [](double ci, double d) { return ci == 0 ? 0.0 : (std::isinf(d) ? 0.0 : ci / d); };
  double best[kNodes] = {0, 0};
  if (c[0] == 0 && c[1] == 0) {
    best[0] = best[1] = kInf;  // (treated below: no losses to detect)
  } else if (c[0] == 0 || c[1] == 0) {
    const std::size_t i = c[0] == 0 ? 1 : 0;  // the lossy node; the other keeps d̄ = 0
    best[i] = sup([&](double d) { return i == 0 ? feasible(d, 0) : feasible(0, d); });
    best[1 - i] = kInf;
  } else if (feasible(kInf, kInf)) {
    best[0] = best[1] = kInf;
  } else {
    const double d1max = sup([&](double d) { return feasible(d, 0); });
    auto g = [&](double d1) { return sup([&](double d2) { return feasible(d1, d2); }); };
    auto f = [&](double d1) { return rate(c[0], d1) + rate(c[1], g(d1)); };
    // Log grid of d̄1 along the edge, then golden section around the best point.
    std::vector<double> grid;
    const double top = std::isinf(d1max) ? 1e6 : d1max;
    for (int k = 0; k <= 24; ++k) grid.push_back(top * std::pow(10.0, -6.0 + 6.0 * k / 24));
    if (std::isinf(d1max)) grid.push_back(kInf);
    std::size_t arg = 0;
    double fbest = kInf;
    std::vector<double> fv(grid.size());
    for (std::size_t k = 0; k < grid.size(); ++k) {
      fv[k] = f(grid[k]);
      if (fv[k] < fbest) {
        fbest = fv[k];
        arg = k;
      }
    }
    double d1 = grid[arg];
    if (std::isfinite(d1) && arg > 0 && arg + 1 < grid.size() && std::isfinite(grid[arg + 1])) {
      double a = std::log(grid[arg - 1]), b = std::log(grid[arg + 1]);
      const double phi = 0.5 * (std::sqrt(5.0) - 1);
      double x1 = b - phi * (b - a), x2 = a + phi * (b - a);
      double f1 = f(std::exp(x1)), f2 = f(std::exp(x2));
      for (int it = 0; it < 30; ++it) {
        if (f1 < f2) {
          b = x2; x2 = x1; f2 = f1; x1 = b - phi * (b - a); f1 = f(std::exp(x1));
        } else {
          a = x1; x1 = x2; f1 = f2; x2 = a + phi * (b - a); f2 = f(std::exp(x2));
        }
      }
      const double cand = std::exp(f1 < f2 ? x1 : x2);
      if (f(cand) < fbest) d1 = cand;
    }
    best[0] = d1;
    best[1] = g(d1);
  }
  const std::vector<double> pd = prior_riccati_diag(model, in.delta_y, best);
  out.p_diag[0] = pd[0];
  out.p_diag[1] = pd[1];
  for (std::size_t i = 0; i < kNodes; ++i) {
    if (pd[i] >= in.mu * p0[i] * (1 - 1e-6)) out.active.push_back("P" + std::to_string(i + 1) + std::to_string(i + 1) + " <= mu P0_" + std::to_string(i + 1) + std::to_string(i + 1));
  }
  for (std::size_t i = 0; i < kNodes; ++i) {
    NodeDeltaT& nd = out.node[i];
    nd.dbar = best[i];
    if (c[i] == 0) {
      nd.bounded = false;
      nd.reason = "loss rate 0: silence never hides a loss (d_i = 0 at any delta_t), rule (2b) not needed";
    } else if (std::isinf(best[i])) {
      nd.bounded = false;
      nd.reason = "diag P <= mu diag P0 holds even with node " + std::to_string(i + 1) +
                  "'s held values worthless (d_" + std::to_string(i + 1) + " -> infinity): no constraint binds, rule (2b) off";
    } else {
      nd.delta_t_s = best[i] * in.mean_gap_s[i] / in.loss[i];  // (7) solved for δt
      nd.delta_t_times_loss = nd.delta_t_s * in.loss[i];
      nd.n_t = static_cast<std::uint32_t>(std::max(1.0, std::round(nd.delta_t_s / model.period_s())));
      out.packets_per_s += 1 / nd.delta_t_s;  // (5)
    }
  }
  // Check against a grid of the (d̄1, d̄2) plane (∞ included).
  if (c[0] > 0 && c[1] > 0) {
    std::vector<double> g;
    for (int k = 0; k <= 24; ++k) g.push_back(std::pow(10.0, -3.0 + 7.0 * k / 24));
    g.push_back(kInf);
    double fgrid = kInf;
    for (double a : g)
      for (double b : g)
        if (feasible(a, b)) fgrid = std::min(fgrid, rate(c[0], a) + rate(c[1], b));
    out.grid_best_packets_per_s = fgrid;
    out.grid_check_passed = out.packets_per_s <= fgrid * (1 + 1e-9);
  } else {
    out.grid_best_packets_per_s = out.packets_per_s;
    out.grid_check_passed = true;
  }
  return out;
}

}  // namespace oneshot::sod
