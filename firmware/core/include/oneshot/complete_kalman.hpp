/// @file complete_kalman.hpp
/// @brief Complete Kalman filter inside the one-shot task model.
///
/// Predicts and corrects sample to sample over the irregular interval
/// a + b with a = τ_k (sample k to actuation t_k, input u_{k−1}) and b = h − τ_{k+1}
/// (t_k to sample k+1, input u_k). update(τ_{k+1}, y):
///   x̂⁻_s,k+1 = Φ(a+b) x̂_s,k + Φ(b) Γ(a) u_{k−1} + Γ(b) u_k
///   P⁻_s,k+1 = Φ(a+b) P_s,k Φ(a+b)ᵀ + Φ(b) Q Φ(b)ᵀ + Q      (constant Q)
///            = Φ(a+b) P_s,k Φ(a+b)ᵀ + Q_d(a+b)              (exact Q_d)
///   correct with y, then x̂_{k+1} = Φ(τ_{k+1}) x̂_s,k+1 + Γ(τ_{k+1}) u_k.
/// Φ is evaluated at three arguments per job (a+b up to 2h, b, τ_{k+1}); Γ(a) is the
/// Γ(τ_k) of the previous job's actuation prediction. The reset state is an estimate at
/// an actuation instant (a = 0, as for the half filter), so the first job adds no
/// constant Q for interval a: both filters then produce the same estimates.
#pragma once

#include <cstddef>
#include <cstdint>

#include "oneshot/kalman_correction.hpp"
#include "oneshot/one_shot_predictor.hpp"

namespace oneshot {

/// Complete Kalman filter; Disc is a GenericDiscretizer or TableDiscretizer.
template <typename Fmt, typename Structure, typename Disc,
          CovarianceUpdate kForm = CovarianceUpdate::kSymmetric>
class CompleteKalman {
 public:
  static constexpr std::size_t kN = Structure::kStates;
  static constexpr std::size_t kM = Structure::kInputs;
  static constexpr std::size_t kP = Structure::kOutputs;
  using Design = ControllerDesign<Fmt, kN, kM, kP>;
  using StateVec = Vector<typename Fmt::State, kN>;
  using OutputVec = Vector<typename Fmt::State, kP>;
  using InputVec = Vector<typename Fmt::Input, kM>;
  using Cov = Matrix<typename Fmt::Covariance, kN, kN>;
  using Gain = Matrix<typename Fmt::KalmanGain, kN, kP>;

  /// Filter over `design` and `disc` (both must outlive it).
  constexpr CompleteKalman(const Design& design, const Disc& disc, NoiseModel noise)
      : design_(&design), disc_(&disc), noise_(noise) {
    reset(StateVec{}, design.p0, InputVec{});
  }

  /// Estimate x0 with covariance p0 at an actuation instant, input u0 applied there
  /// (treated as a sample with τ = 0).
  constexpr void reset(const StateVec& x0, const Cov& p0, const InputVec& u0) {
    xs_ = x0;
    x_ = x0;
    p_ = p0;
    u_before_ = u0;
    u_ = u0;
    gamma_a_ = Matrix<typename Fmt::InputGain, kN, kM>{};
    tau_prev_us_ = 0;
    first_job_ = true;
    k_ = Gain{};
  }

  /// Job with sample y taken tau_us before the next actuation instant.
  constexpr Status update(std::int32_t tau_us, const OutputVec& y) {
    tau_us = disc_->quantize(tau_us);  // the discretizer's sub-grid policy
    using PhiP = typename Structure::PhiPattern;
    using GammaP = typename Structure::GammaPattern;
    using CovT = typename Fmt::Covariance;
    const std::int32_t b_us = design_->period_us - tau_us;
    typename Disc::Triple sum{NoInit{}};
    typename Disc::Triple b{NoInit{}};
    Status status = disc_->discretize(b_us + tau_prev_us_, sum, qd_needed(noise_));
    status = first_failure(status, disc_->discretize(b_us, b, WithQd::kNo));
    // x̂⁻ = Φ(a+b) x̂_s + Φ(b)(Γ(a) u_{k−1}) + Γ(b) u_k.
    const Vector<typename Fmt::State, kN> gu =
        product<typename Fmt::State, GammaP, Dense<kM, 1>>(gamma_a_, u_before_);
    const Vector<typename Fmt::State, kN> carried =
        affine<typename Fmt::State, PhiP, GammaP>(b.phi, gu, b.gamma, u_);
    for (std::size_t i = 0; i < kN; ++i) {
      Accumulator<typename Fmt::State> acc;
      for (std::size_t j = 0; j < kN; ++j)
        detail::accumulate_term(acc, PhiP::is_zero(i, j), PhiP::is_one(i, j), sum.phi(i, j), false,
                                false, xs_[j]);
      acc.add(carried[i]);
      x_[i] = acc.value();
    }
    if (noise_ == NoiseModel::kExact) {
      p_ = congruence_add<CovT, PhiP, typename Structure::QdPattern>(sum.phi, p_, sum.qd);
    } else {
      using QP = typename Structure::ConstantQPattern;
      if (first_job_) {
        p_ = congruence_add<CovT, PhiP, QP>(sum.phi, p_, design_->q_constant);
      } else {
        const Cov q_b = congruence_add<CovT, PhiP, QP>(b.phi, design_->q_constant, design_->q_constant);
        p_ = congruence_add<CovT, PhiP, Dense<kN, kN>>(sum.phi, p_, q_b);
      }
    }
    status = first_failure(status, correct<Fmt, Structure, kForm>(x_, p_, y, design_->c, design_->r, k_));
    xs_ = x_;
    typename Disc::Triple c{NoInit{}};
    status = first_failure(status, disc_->discretize(tau_us, c, WithQd::kNo));
    x_ = predict_state<Fmt, Structure>(c, xs_, u_);
    gamma_a_ = c.gamma;
    tau_prev_us_ = tau_us < 0 ? 0 : tau_us;
    first_job_ = false;
    return status;
  }

  /// The input applied at the actuation instant the last update predicted to.
  constexpr void set_applied_input(const InputVec& u) {
    u_before_ = u_;
    u_ = u;
  }
  /// x̂_k: the estimate at the next actuation instant.
  constexpr const StateVec& prediction() const { return x_; }
  /// P_s,k: the corrected covariance at the last sample.
  constexpr const Cov& covariance() const { return p_; }
  /// The gain of the last correction.
  constexpr const Gain& gain() const { return k_; }

 private:
  const Design* design_;
  const Disc* disc_;
  NoiseModel noise_;
  StateVec xs_{};   // x̂_s,k at the last sample
  StateVec x_{};    // prediction to the next actuation
  Cov p_{};         // P_s,k
  InputVec u_before_{};  // u_{k−1}
  InputVec u_{};         // u_k
  Matrix<typename Fmt::InputGain, kN, kM> gamma_a_{};  // Γ(τ_k)
  std::int32_t tau_prev_us_ = 0;
  bool first_job_ = true;
  Gain k_{};
};

}  // namespace oneshot
