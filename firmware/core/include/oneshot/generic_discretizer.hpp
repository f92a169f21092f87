/// @file generic_discretizer.hpp
/// @brief Φ(τ), Γ(τ), Q_d(τ) for any τ and any plant by matrix exponentials.
///
/// Φ and Γ come from one exponential of the (n+m)×(n+m) block matrix
///   exp([[A, B], [0, 0]]·t) = [[Φ(t), Γ(t)], [0, I]],
/// and Q_d from Van Loan's 2n×2n construction
///   exp([[−A, Q_c], [0, Aᵀ]]·t) = [[·, F₁₂], [0, F₂₂]],  Φ = F₂₂ᵀ,  Q_d = F₂₂ᵀ F₁₂.
/// Slower than the table, no table memory, works for every plant the exponential does.
#pragma once

#include <cstddef>
#include <cstdint>

#include "oneshot/discretization.hpp"
#include "oneshot/matrix_exponential.hpp"
#include "oneshot/status.hpp"

namespace oneshot {

/// Continuous model with time in microseconds: A_us = A·10⁻⁶ s, B_us = B·10⁻⁶,
/// Qc_us = Q_c·10⁻⁶, so that M·t = M_us·τ_us with an exact integer τ_us.
template <typename S, std::size_t N, std::size_t M>
struct ContinuousModelPerUs {
  Matrix<S, N, N> a_per_us;   ///< A (1/µs).
  Matrix<S, N, M> b_per_us;   ///< B (state unit per input unit per µs).
  Matrix<S, N, N> qc_per_us;  ///< Q_c (V²/µs).
};

/// Discretizer computing every call with matrix exponentials in Fmt::Compute.
template <typename Fmt, std::size_t N, std::size_t M>
class GenericDiscretizer {
 public:
  using Compute = typename Fmt::Compute;
  using Model = ContinuousModelPerUs<Compute, N, M>;
  using Triple = Discretization<Fmt, N, M>;  ///< What discretize() produces.

  /// Uses `model` (copied).
  constexpr explicit GenericDiscretizer(const Model& model) : model_(model) {}

  /// Φ, Γ (and Q_d when asked) over τ_us ≥ 0 microseconds. Negative τ is clamped to 0
  /// (kClamped); kOutOfRange when the exponential cannot be scaled.
  constexpr Status discretize(std::int32_t tau_us, Discretization<Fmt, N, M>& out,
                              WithQd with_qd) const {
    Status status = Status::kOk;
    if (tau_us < 0) {
      tau_us = 0;
      status = Status::kClamped;
    }
    const Compute t = ScalarTraits<Compute>::from_int(tau_us);
    Matrix<Compute, N + M, N + M> block;
    block.template set_block<0, 0>(model_.a_per_us * t);
    block.template set_block<0, N>(model_.b_per_us * t);
    Matrix<Compute, N + M, N + M> e;
    const Status s1 = matrix_exponential(block, e);
    if (s1 != Status::kOk) return s1;
    out.phi = convert_matrix<typename Fmt::Transition>(e.template block<0, 0, N, N>());
    out.gamma = convert_matrix<typename Fmt::InputGain>(e.template block<0, N, N, M>());
    if (with_qd == WithQd::kYes) {
      Matrix<Compute, 2 * N, 2 * N> van_loan;
      van_loan.template set_block<0, 0>(-(model_.a_per_us * t));
      van_loan.template set_block<0, N>(model_.qc_per_us * t);
      van_loan.template set_block<N, N>(model_.a_per_us.transposed() * t);
      Matrix<Compute, 2 * N, 2 * N> f;
      const Status s2 = matrix_exponential(van_loan, f);
      if (s2 != Status::kOk) return s2;
      Matrix<Compute, N, N> qd = f.template block<N, N, N, N>().transposed() *
                                 f.template block<0, N, N, N>();
      mirror_upper(qd);  // exact symmetry; the product is symmetric up to rounding
      out.qd = convert_matrix<typename Fmt::Covariance>(qd);
    }
    return status;
  }

  /// The model in use.
  constexpr const Model& model() const { return model_; }

 private:
  Model model_;
};

}  // namespace oneshot
