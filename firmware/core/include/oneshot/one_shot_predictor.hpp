/// @file one_shot_predictor.hpp
/// @brief Prediction over an interval: the one-shot step from a sample to an actuation.
///
///   x̂(t+τ) = Φ(τ) x̂(t) + Γ(τ) u,    P(t+τ) = Φ(τ) P Φ(τ)ᵀ + Q,
/// with Q the constant per-step covariance (original design) or Q_d(τ) (exact).
#pragma once

#include <cstddef>

#include "oneshot/controller_design.hpp"
#include "oneshot/discretization.hpp"
#include "oneshot/structured_ops.hpp"

namespace oneshot {

/// Φ(τ) x + Γ(τ) u.
template <typename Fmt, typename Structure, std::size_t N, std::size_t M>
constexpr Vector<typename Fmt::State, N> predict_state(const Discretization<Fmt, N, M>& d,
                                                       const Vector<typename Fmt::State, N>& x,
                                                       const Vector<typename Fmt::Input, M>& u) {
  return affine<typename Fmt::State, typename Structure::PhiPattern, typename Structure::GammaPattern>(
      d.phi, x, d.gamma, u);
}

/// Φ(τ) P Φ(τ)ᵀ + (Q_d(τ) | Q_constant).
template <typename Fmt, typename Structure, std::size_t N, std::size_t M>
constexpr Matrix<typename Fmt::Covariance, N, N> predict_covariance(
    const Discretization<Fmt, N, M>& d, const Matrix<typename Fmt::Covariance, N, N>& p,
    NoiseModel noise, const Matrix<typename Fmt::Covariance, N, N>& q_constant) {
  using PhiP = typename Structure::PhiPattern;
  if (noise == NoiseModel::kExact)
    return congruence_add<typename Fmt::Covariance, PhiP, typename Structure::QdPattern>(d.phi, p, d.qd);
  return congruence_add<typename Fmt::Covariance, PhiP, typename Structure::ConstantQPattern>(
      d.phi, p, q_constant);
}

/// Whether the discretizer must deliver Q_d for this noise model.
constexpr WithQd qd_needed(NoiseModel noise) {
  return noise == NoiseModel::kExact ? WithQd::kYes : WithQd::kNo;
}

}  // namespace oneshot
