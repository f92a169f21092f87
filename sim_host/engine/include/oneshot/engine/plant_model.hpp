/// @file plant_model.hpp
/// @brief Plant models from plain matrices (run-time sizes), checked against the
///        compile-time dimensions of the study that uses them.
///
/// A study knows its dimensions at compile time (ContinuousPlant<N, M, P, W>); a model
/// read from a file has run-time sizes. make_continuous_config() / make_discrete_config()
/// convert, refusing a model whose dimensions differ with both named ("plant has n = 3,
/// m = 1, p = 1, 0 disturbance inputs; study 'ncs' expects n = 2, m = 1, p = 2, 1").
/// An absent B_w / Γ_w is zero; absent cost weights are zero.
#pragma once

#include <cstddef>
#include <stdexcept>
#include <string>

#include "oneshot/design/dense_matrix.hpp"
#include "oneshot/engine/continuous_plant.hpp"
#include "oneshot/engine/discrete_plant.hpp"

namespace oneshot::engine {

using design::DenseMatrix;

/// ẋ = A x + B u + B_w d + w, y = C x, E[w wᵀ] = Q_c δ; cost weights Q1c, Q2c.
struct ContinuousModel {
  DenseMatrix a, b, bw, c, qc, q1c, q2c;  ///< Matrices (bw, q1c, q2c may be empty).
};

/// x⁺ = Φ x + Γ u + Γ_w d + w, y = C x, E[w wᵀ] = Q per step of `period`; cost Q1, Q2 per step.
struct DiscreteModel {
  DenseMatrix phi, gamma, gamma_w, c, q, q1, q2;  ///< Matrices (gamma_w, q1, q2 may be empty).
  Duration period{0};                             ///< Step length.
};

namespace detail {
inline std::string dims(std::size_t n, std::size_t m, std::size_t p, std::size_t w) {
  return "n = " + std::to_string(n) + ", m = " + std::to_string(m) + ", p = " + std::to_string(p) + ", " +
         std::to_string(w) + " disturbance input(s)";
}
template <std::size_t R, std::size_t C>
Matrix<double, R, C> fixed(const DenseMatrix& d, const char* what) {
  Matrix<double, R, C> m;
  if (d.rows == 0 && d.cols == 0) return m;  // absent: zero
  if (d.rows != R || d.cols != C) {
    throw std::invalid_argument(std::string("plant model: ") + what + " is " + std::to_string(d.rows) + "x" +
                                std::to_string(d.cols) + ", expected " + std::to_string(R) + "x" + std::to_string(C));
  }
  for (std::size_t k = 0; k < R * C; ++k) m[k] = d.values[k];
  return m;
}
inline void check_dims(std::size_t n, std::size_t m, std::size_t p, std::size_t w, std::size_t en, std::size_t em,
                       std::size_t ep, std::size_t ew, const std::string& study) {
  if (n != en || m != em || p != ep || (w != 0 && w != ew)) {
    throw std::invalid_argument("plant has " + dims(n, m, p, w) + "; study '" + study + "' expects " +
                                dims(en, em, ep, ew));
  }
}
}  // namespace detail

/// The ContinuousPlant configuration of `model` for a study of dimensions N, M, P, W.
template <std::size_t N, std::size_t M, std::size_t P, std::size_t W>
ContinuousPlantConfig<N, M, P, W> make_continuous_config(const ContinuousModel& model, const std::string& study) {
  detail::check_dims(model.a.rows, model.b.cols, model.c.rows, model.bw.cols, N, M, P, W, study);
  ContinuousPlantConfig<N, M, P, W> c;
  c.a = detail::fixed<N, N>(model.a, "A");
  c.b = detail::fixed<N, M>(model.b, "B");
  c.bw = detail::fixed<N, W>(model.bw, "B_w");
  c.c = detail::fixed<P, N>(model.c, "C");
  c.qc = detail::fixed<N, N>(model.qc, "Q_c");
  c.q1c = detail::fixed<N, N>(model.q1c, "Q1c");
  c.q2c = detail::fixed<M, M>(model.q2c, "Q2c");
  return c;
}

/// The DiscretePlant configuration of `model` for a study of dimensions N, M, P, W.
template <std::size_t N, std::size_t M, std::size_t P, std::size_t W>
DiscretePlantConfig<N, M, P, W> make_discrete_config(const DiscreteModel& model, const std::string& study) {
  detail::check_dims(model.phi.rows, model.gamma.cols, model.c.rows, model.gamma_w.cols, N, M, P, W, study);
  if (model.period.count() <= 0) throw std::invalid_argument("plant model: the period must be positive");
  DiscretePlantConfig<N, M, P, W> c;
  c.phi = detail::fixed<N, N>(model.phi, "Phi");
  c.gamma = detail::fixed<N, M>(model.gamma, "Gamma");
  c.gamma_w = detail::fixed<N, W>(model.gamma_w, "Gamma_w");
  c.c = detail::fixed<P, N>(model.c, "C");
  c.q = detail::fixed<N, N>(model.q, "Q");
  c.q1 = detail::fixed<N, N>(model.q1, "Q1");
  c.q2 = detail::fixed<M, M>(model.q2, "Q2");
  c.period = model.period;
  return c;
}

}  // namespace oneshot::engine
