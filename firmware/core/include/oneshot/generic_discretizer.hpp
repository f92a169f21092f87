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
#include "oneshot/fixed_point.hpp"
#include "oneshot/matrix_exponential.hpp"
#include "oneshot/status.hpp"

namespace oneshot {

/// Continuous model with time in microseconds: A_us = A·10⁻⁶ s, B_us = B·10⁻⁶,
/// Qc_us = Q_c·10⁻⁶·2^k (k = Fmt::kQdScaleShift), so that M·t = M_us·τ_us with an exact
/// integer τ_us. The per-µs entries are tiny: fixed point stores them in their own
/// formats (Sa, Sb, Sq), floating point in S.
template <typename S, std::size_t N, std::size_t M, typename Sa = S, typename Sb = S, typename Sq = S>
struct ContinuousModelPerUs {
  Matrix<Sa, N, N> a_per_us;   ///< A (1/µs).
  Matrix<Sb, N, M> b_per_us;   ///< B (state unit per input unit per µs).
  Matrix<Sq, N, N> qc_per_us;  ///< Q_c·2^k (V²/µs).
};

/// Entry-wise m·t delivered in format Out.
template <typename Out, typename S, typename T, std::size_t R, std::size_t C>
constexpr Matrix<Out, R, C> scaled(const Matrix<S, R, C>& m, T t) {
  Matrix<Out, R, C> out;
  for (std::size_t k = 0; k < R * C; ++k) out[k] = mul<Out>(m[k], t);
  return out;
}

/// v·2^−kShift delivered in format Out: for fixed point a change of scale, no arithmetic.
template <typename Out, int kShift, typename S>
constexpr Out unscale_qd(S v) {
  if constexpr (kIsFloating<S>) {
    static_assert(kShift >= 0 && kShift < 63, "scale shift out of range");
    constexpr S kScale = ScalarTraits<S>::from_ratio(1, std::int64_t{1} << kShift);  // exact power of two
    return convert<Out>(v * kScale);
  } else {
    return convert<Out>(Fixed<typename S::StorageType, S::kFrac + kShift>::from_raw(v.raw()));
  }
}

/// Discretizer computing every call with matrix exponentials in Fmt::Compute.
template <typename Fmt, std::size_t N, std::size_t M>
class GenericDiscretizer {
 public:
  using Compute = typename Fmt::Compute;
  using Model = ContinuousModelPerUs<Compute, N, M, typename Fmt::ModelA, typename Fmt::ModelB, typename Fmt::ModelQc>;
  using Triple = Discretization<Fmt, N, M>;  ///< What discretize() produces.

  /// Uses `model` (copied).
  constexpr explicit GenericDiscretizer(const Model& model) : model_(model) {}

  /// τ as the filters use it: exact.
  constexpr std::int32_t quantize(std::int32_t tau_us) const { return tau_us; }

  /// Φ, Γ (and Q_d when asked) over τ_us ≥ 0 microseconds. Negative τ is clamped to 0
  /// (kClamped); kOutOfRange when the exponential cannot be scaled.
  [[nodiscard]] constexpr Status discretize(std::int32_t tau_us, Discretization<Fmt, N, M>& out,
                              WithQd with_qd) const {
    Status status = Status::kOk;
    if (tau_us < 0) {
      tau_us = 0;
      status = Status::kClamped;
    }
    const auto t = count_of<Compute>(tau_us);
    Matrix<Compute, N + M, N + M> block;
    block.template set_block<0, 0>(scaled<Compute>(model_.a_per_us, t));
    block.template set_block<0, N>(scaled<Compute>(model_.b_per_us, t));
    Matrix<Compute, N + M, N + M> e;
    const Status s1 = matrix_exponential(block, e);
    if (s1 != Status::kOk) return s1;
    out.phi = convert_matrix<typename Fmt::Transition>(e.template block<0, 0, N, N>());
    out.gamma = convert_matrix<typename Fmt::InputGain>(e.template block<0, N, N, M>());
    if (with_qd == WithQd::kYes) {
      // Q_d is linear in Q_c: run Van Loan on Q_c·2^k (qc_per_us holds it) and undo 2^k.
      Matrix<Compute, 2 * N, 2 * N> van_loan;
      const Matrix<Compute, N, N> at = scaled<Compute>(model_.a_per_us, t);
      van_loan.template set_block<0, 0>(-at);
      van_loan.template set_block<0, N>(scaled<Compute>(model_.qc_per_us, t));
      van_loan.template set_block<N, N>(at.transposed());
      Matrix<Compute, 2 * N, 2 * N> f;
      const Status s2 = matrix_exponential(van_loan, f);
      if (s2 != Status::kOk) return s2;
      const Matrix<Compute, N, N> f22t = f.template block<N, N, N, N>().transposed();
      const Matrix<Compute, N, N> f12 = f.template block<0, N, N, N>();
      for (std::size_t i = 0; i < N; ++i)
        for (std::size_t j = i; j < N; ++j) {
          Accumulator<Compute> acc;
          for (std::size_t k = 0; k < N; ++k) acc.add_product(f22t(i, k), f12(k, j));
          out.qd(i, j) = unscale_qd<typename Fmt::Covariance, Fmt::kQdScaleShift>(acc.value());
        }
      mirror_upper(out.qd);  // Q_d = F₂₂ᵀF₁₂ is symmetric; keep it exactly so
    }
    return status;
  }

  /// The model in use.
  constexpr const Model& model() const { return model_; }

 private:
  Model model_;
};

}  // namespace oneshot
