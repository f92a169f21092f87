/// @file discretization.hpp
/// @brief The triple Φ(t), Γ(t), Q_d(t) and its composition law.
///
///   Φ(t) = e^{At},  Γ(t) = ∫₀ᵗ e^{As} ds B,  Q_d(t) = ∫₀ᵗ e^{As} Q_c e^{Aᵀs} ds.
/// Composition over consecutive intervals a then b (exact):
///   Φ(a+b) = Φ(b)Φ(a),  Γ(a+b) = Φ(b)Γ(a) + Γ(b),  Q_d(a+b) = Φ(b)Q_d(a)Φ(b)ᵀ + Q_d(b).
#pragma once

#include <cstddef>

#include "oneshot/matrix.hpp"
#include "oneshot/structured_ops.hpp"

namespace oneshot {

/// Discrete model of one interval, in the formats of policy Fmt. Q_d is unspecified
/// unless the discretizer was asked for it (WithQd::kYes).
template <typename Fmt, std::size_t N, std::size_t M>
struct Discretization {
  Matrix<typename Fmt::Transition, N, N> phi;    ///< Φ(t).
  Matrix<typename Fmt::InputGain, N, M> gamma;   ///< Γ(t).
  Matrix<typename Fmt::Covariance, N, N> qd;     ///< Q_d(t) (only when requested).

  /// All zero.
  constexpr Discretization() = default;
  /// Entries left unset (the discretizer writes them).
  explicit Discretization(NoInit) : phi(NoInit{}), gamma(NoInit{}), qd(NoInit{}) {}

  /// The zero-length interval: Φ = I, Γ = 0, Q_d = 0.
  static constexpr Discretization identity() {
    Discretization d;
    d.phi = Matrix<typename Fmt::Transition, N, N>::identity();
    return d;
  }
};

/// Whether a discretization must also deliver Q_d(t).
enum class WithQd : bool { kNo = false, kYes = true };

/// d ← d followed by `then` (in place), per the composition law above.
template <typename Fmt, typename Structure, std::size_t N, std::size_t M>
constexpr void compose_into(Discretization<Fmt, N, M>& d, const Discretization<Fmt, N, M>& then, WithQd with_qd) {
  using PhiP = typename Structure::PhiPattern;
  using GammaP = typename Structure::GammaPattern;
  using QdP = typename Structure::QdPattern;
  // Γ(a+b) = Φ(b)Γ(a) + Γ(b): Φ(b) is structured, Γ(a) and Γ(b) share GammaP.
  Matrix<typename Fmt::InputGain, N, M> gamma{NoInit{}};
  for (std::size_t i = 0; i < N; ++i)
    for (std::size_t j = 0; j < M; ++j) {
      if (GammaP::is_zero(i, j)) {
        gamma(i, j) = ScalarTraits<typename Fmt::InputGain>::zero();
        continue;
      }
      Accumulator<typename Fmt::InputGain> acc;
      for (std::size_t k = 0; k < N; ++k)
        detail::accumulate_term(acc, PhiP::is_zero(i, k), PhiP::is_one(i, k), then.phi(i, k),
                                GammaP::is_zero(k, j), GammaP::is_one(k, j), d.gamma(k, j));
      acc.add(then.gamma(i, j));
      gamma(i, j) = acc.value();
    }
  d.gamma = gamma;
  if (with_qd == WithQd::kYes) {
    d.qd = congruence_add<typename Fmt::Covariance, PhiP, QdP>(then.phi, d.qd, then.qd);
  }
  d.phi = product<typename Fmt::Transition, PhiP, PhiP>(then.phi, d.phi);
}

}  // namespace oneshot
