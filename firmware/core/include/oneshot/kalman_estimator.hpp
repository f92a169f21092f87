/// @file kalman_estimator.hpp
/// @brief The estimator every filter is built on: predict over any interval, correct the
///        outputs that arrived with this step's R.
///
/// State: x̂ and P at the estimate instant. Operations (each may be repeated or skipped):
///   predict(d, u):          x̂ ← Φx̂ + Γu,  P ← ΦPΦᵀ + Q_d   (or + the constant Q)
///   predict(disc, Δt, u):   the same with Φ(Δt), Γ(Δt), Q_d(Δt) from a discretizer
///   predict_steps(d, N, u): N steps of a discrete plant (Φ, Γ, Q per step)
///   predict_across(disc, Δt, history): across every input change of an InputHistory,
///       segments d₀ … d_{K−1} (Σ = Δt, the last one ending at Δt) with inputs u₀ … u_{K−1}:
///         x̂ ← Φ(Δt) x̂ + c_K,   c₁ = Γ(d₀)u₀,  c_{k+1} = Φ(d_k) c_k + Γ(d_k) u_k
///         P ← Φ(Δt) P Φ(Δt)ᵀ + Q_d(Δt)                              (exact noise)
///         P ← Φ(Δt) P Φ(Δt)ᵀ + Σ_K,  Σ₁ = Q,  Σ_{k+1} = Φ(d_k) Σ_k Φ(d_k)ᵀ + Q  (constant Q
///             per segment, the original design's "Q per prediction step")
///   correct(y, present, r): sequential scalar updates, one per present output o:
///         s = c_o P c_oᵀ + r_o,  k = P c_oᵀ / s,  x̂ ← x̂ + k (y_o − c_o x̂),
///         P ← (I − k c_o) P (I − k c_o)ᵀ + r_o k kᵀ   (Joseph; kSymmetric: P − k (P c_oᵀ)ᵀ)
///       exact for a diagonal R of this step; an absent output is skipped (predict-only
///       when none is present).
/// Each scalar update is kalman_correction.hpp's one-output update on row o of C, so a
/// one-output filter on this estimator computes the same bits as before it existed.
#pragma once

#include <cstddef>
#include <cstdint>
#include <utility>

#include "oneshot/input_history.hpp"
#include "oneshot/kalman_correction.hpp"
#include "oneshot/one_shot_predictor.hpp"

namespace oneshot {

/// Bit o set: output o is present in this step's measurement.
using OutputMask = std::uint8_t;

/// Every one of P outputs present.
template <std::size_t P>
inline constexpr OutputMask kAllOutputs = static_cast<OutputMask>((1U << P) - 1U);

namespace detail {
/// The structure seen by a one-output update of row O of the output pattern.
template <typename Structure, std::size_t O>
struct OutputRowStructure {
  using OutputPattern = RowOf<typename Structure::OutputPattern, O>;
};
}  // namespace detail

/// Kalman estimator of an n-state plant with the patterns of Structure.
template <typename Fmt, typename Structure, CovarianceUpdate kForm = CovarianceUpdate::kJoseph>
class KalmanEstimator {
 public:
  static constexpr std::size_t kN = Structure::kStates;
  static constexpr std::size_t kM = Structure::kInputs;
  static constexpr std::size_t kP = Structure::kOutputs;
  static_assert(within_dimension_limits(kN, kM, kP),
                "plant dimensions exceed kMaxStates (16), kMaxInputs (4) or kMaxOutputs (4)");
  using StateVec = Vector<typename Fmt::State, kN>;        ///< x̂.
  using OutputVec = Vector<typename Fmt::State, kP>;       ///< y.
  using InputVec = Vector<typename Fmt::Input, kM>;        ///< u.
  using Cov = Matrix<typename Fmt::Covariance, kN, kN>;    ///< P.
  using Gain = Matrix<typename Fmt::KalmanGain, kN, kP>;   ///< K (column o: output o).
  using OutputMatrix = Matrix<typename Fmt::Transition, kP, kN>;  ///< C.
  using OutputVariances = Vector<typename Fmt::Covariance, kP>;   ///< diag R of this step.
  using InputGain = Matrix<typename Fmt::InputGain, kN, kM>;      ///< Γ.
  using Triple = Discretization<Fmt, kN, kM>;              ///< Φ, Γ, Q_d of one interval.

  /// Estimate x0 with covariance p0.
  constexpr void reset(const StateVec& x0, const Cov& p0) {
    x_ = x0;
    p_ = p0;
    k_ = Gain{};
  }

  /// One interval with constant input u: noise Q_d of d (kExact) or q_constant.
  constexpr void predict(const Triple& d, const InputVec& u, NoiseModel noise, const Cov& q_constant) {
    x_ = predict_state<Fmt, Structure>(d, x_, u);
    p_ = predict_covariance<Fmt, Structure>(d, p_, noise, q_constant);
  }

  /// One interval of dt_us with constant input u, discretized by `disc`.
  template <typename Disc>
  [[nodiscard]] constexpr Status predict(const Disc& disc, DurationUs dt_us, const InputVec& u, NoiseModel noise,
                           const Cov& q_constant) {
    Triple d{NoInit{}};
    const Status status = disc.discretize(dt_us, d, qd_needed(noise));
    predict(d, u, noise, q_constant);
    return status;
  }

  /// `steps` steps of a discrete plant x⁺ = Φx + Γu + w, E[wwᵀ] = step.qd.
  constexpr void predict_steps(const Triple& step, std::uint32_t steps, const InputVec& u) {
    for (std::uint32_t s = 0; s < steps; ++s) predict(step, u, NoiseModel::kExact, step.qd);
  }

  /// dt_us across every entry of `history` (equations above; the caller keeps in it the
  /// changes within the interval: an offset beyond dt_us makes a negative last segment,
  /// which the discretizer clamps to 0 and reports). `first_gamma`: Γ(d₀) when the caller
  /// has it (nullptr: computed); `first_segment_noise` false: segment 0 adds no constant Q
  /// (a zero-length segment standing for a reset). history is not modified.
  template <typename Disc, std::size_t kCap>
  [[nodiscard]] constexpr Status predict_across(const Disc& disc, DurationUs dt_us,
                                  const InputHistory<typename Fmt::Input, kM, kCap>& history, NoiseModel noise,
                                  const Cov& q_constant, const InputGain* first_gamma = nullptr,
                                  bool first_segment_noise = true) {
    using PhiP = typename Structure::PhiPattern;
    using GammaP = typename Structure::GammaPattern;
    using QP = typename Structure::ConstantQPattern;
    using CovT = typename Fmt::Covariance;
    Triple total{NoInit{}};
    Status status = disc.discretize(dt_us, total, qd_needed(noise));
    const std::size_t segments = history.size();
    StateVec carried{NoInit{}};
    Cov sigma{NoInit{}};
    enum class Sigma : std::uint8_t { kNone, kQ, kDense } sigma_kind = Sigma::kNone;
    for (std::size_t k = 0; k < segments; ++k) {
      const DurationUs end_us = k + 1 < segments ? history.offset_us(k + 1) : dt_us;
      const DurationUs length_us = end_us - history.offset_us(k);
      const InputVec& u = history.input(k);
      if (k == 0) {
        // c₁ = Γ(d₀) u₀ (no Φ(d₀) needed: c₀ = 0).
        if (first_gamma != nullptr) {
          carried = product<typename Fmt::State, GammaP, Dense<kM, 1>>(*first_gamma, u);
        } else {
          Triple seg{NoInit{}};
          status = worst_of(status, disc.discretize(length_us, seg, WithQd::kNo));
          carried = product<typename Fmt::State, GammaP, Dense<kM, 1>>(seg.gamma, u);
        }
        if (first_segment_noise) sigma_kind = Sigma::kQ;
        continue;
      }
      Triple seg{NoInit{}};
      status = worst_of(status, disc.discretize(length_us, seg, WithQd::kNo));
      carried = affine<typename Fmt::State, PhiP, GammaP>(seg.phi, carried, seg.gamma, u);
      if (noise == NoiseModel::kConstant) {
        if (sigma_kind == Sigma::kNone) {
          sigma_kind = Sigma::kQ;
        } else if (sigma_kind == Sigma::kQ) {
          sigma = congruence_add<CovT, PhiP, QP>(seg.phi, q_constant, q_constant);
          sigma_kind = Sigma::kDense;
        } else {
          sigma = congruence_add<CovT, PhiP, QP>(seg.phi, sigma, q_constant);
        }
      }
    }
    // x̂ ← Φ(Δt) x̂ + c_K.
    StateVec x{NoInit{}};
    for (std::size_t i = 0; i < kN; ++i) {
      Accumulator<typename Fmt::State> acc;
      for (std::size_t j = 0; j < kN; ++j)
        detail::accumulate_term(acc, PhiP::is_zero(i, j), PhiP::is_one(i, j), total.phi(i, j), false, false, x_[j]);
      acc.add(carried[i]);
      x[i] = acc.value();
    }
    x_ = x;
    if (noise == NoiseModel::kExact) {
      p_ = congruence_add<CovT, PhiP, typename Structure::QdPattern>(total.phi, p_, total.qd);
    } else if (sigma_kind == Sigma::kQ) {
      p_ = congruence_add<CovT, PhiP, QP>(total.phi, p_, q_constant);
    } else if (sigma_kind == Sigma::kDense) {
      p_ = congruence_add<CovT, PhiP, Dense<kN, kN>>(total.phi, p_, sigma);
    } else {
      p_ = congruence<CovT, PhiP>(total.phi, p_);
    }
    return status;
  }

  /// Sequential scalar updates with the outputs of `present` (equations above), R of this
  /// step diagonal (variances r). kSingular when an innovation variance is not positive
  /// (that output skipped, its gain column kept, the others still applied). Gain column
  /// o: the gain used for output o, zero when absent.
  [[nodiscard]] constexpr Status correct(const OutputVec& y, OutputMask present, const OutputVariances& r, const OutputMatrix& c) {
    return correct_rows(y, present, r, c, std::make_index_sequence<kP>{});
  }

  /// Every output with the full R: the scalar update for one output, the joint update
  /// (kalman_correction.hpp, any symmetric R) for several.
  [[nodiscard]] constexpr Status correct_all(const OutputVec& y, const OutputMatrix& c,
                               const Matrix<typename Fmt::Covariance, kP, kP>& r) {
    if constexpr (kP == 1) {
      OutputVariances rv;
      rv[0] = r(0, 0);
      return correct(y, kAllOutputs<kP>, rv, c);
    } else {
      return oneshot::correct<Fmt, Structure, kForm>(x_, p_, y, c, r, k_);
    }
  }

  /// x̂ at the estimate instant.
  constexpr const StateVec& state() const { return x_; }
  /// P at the estimate instant.
  constexpr const Cov& covariance() const { return p_; }
  /// The gain of the last correction.
  constexpr const Gain& gain() const { return k_; }

 private:
  template <std::size_t... O>
  [[nodiscard]] constexpr Status correct_rows(const OutputVec& y, OutputMask present, const OutputVariances& r,
                                const OutputMatrix& c, std::index_sequence<O...>) {
    Status status = Status::kOk;
    ((status = worst_of(status, correct_row<O>(y, present, r, c))), ...);
    return status;
  }

  template <std::size_t O>
  [[nodiscard]] constexpr Status correct_row(const OutputVec& y, OutputMask present, const OutputVariances& r,
                               const OutputMatrix& c) {
    Matrix<typename Fmt::KalmanGain, kN, 1> k{};  // absent output: zero gain
    Status status = Status::kOk;
    if (((static_cast<unsigned>(present) >> O) & 1U) != 0U) {
      for (std::size_t i = 0; i < kN; ++i) k(i, 0) = k_(i, O);  // kept when singular
      Vector<typename Fmt::State, 1> yo;
      yo[0] = y[O];
      Matrix<typename Fmt::Transition, 1, kN> co{NoInit{}};
      for (std::size_t j = 0; j < kN; ++j) co(0, j) = c(O, j);
      Matrix<typename Fmt::Covariance, 1, 1> ro;
      ro(0, 0) = r[O];
      status = oneshot::correct<Fmt, detail::OutputRowStructure<Structure, O>, kForm>(x_, p_, yo, co, ro, k);
    }
    for (std::size_t i = 0; i < kN; ++i) k_(i, O) = k(i, 0);
    return status;
  }

  StateVec x_{};
  Cov p_{};
  Gain k_{};
};

}  // namespace oneshot
