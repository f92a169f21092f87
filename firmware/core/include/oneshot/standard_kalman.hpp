/// @file standard_kalman.hpp
/// @brief Kalman filter of the standard task model: fixed period h, zero sampling delay.
///
/// The standard controller assumes samples exactly h apart and actuation at the sampling
/// instant; update(·, y) therefore ignores τ:
///   x̂⁻ = Φ(h) x̂ + Γ(h) u,  P⁻ = Φ(h) P Φ(h)ᵀ + Q   (skipped at the first sample)
///   correct with y;  u = −L x̂ is applied as soon as the job finishes.
/// Under scheduling jitter both assumptions break, which is what approach D measures.
/// Built on KalmanEstimator: one step of the discrete model, one correction.
#pragma once

#include <cstddef>
#include <cstdint>

#include "oneshot/kalman_estimator.hpp"

namespace oneshot {

/// Time-varying Kalman filter on the nominal discrete model (Φ(h), Γ(h)).
template <typename Fmt, typename Structure, CovarianceUpdate kForm = CovarianceUpdate::kSymmetric>
class StandardKalman {
 public:
  static constexpr std::size_t kN = Structure::kStates;
  static constexpr std::size_t kM = Structure::kInputs;
  static constexpr std::size_t kP = Structure::kOutputs;
  using Design = ControllerDesign<Fmt, kN, kM, kP>;
  using Core = KalmanEstimator<Fmt, Structure, kForm>;  ///< The estimator it runs on.
  using StateVec = typename Core::StateVec;
  using OutputVec = typename Core::OutputVec;
  using InputVec = typename Core::InputVec;
  using Cov = typename Core::Cov;
  using Gain = typename Core::Gain;

  /// Filter over `design` (must outlive it).
  constexpr StandardKalman(const Design& design, NoiseModel noise) : design_(&design), noise_(noise) {
    reset(StateVec{}, design.p0, InputVec{});
  }

  /// Estimate x0 with covariance p0 at the first sampling instant.
  constexpr void reset(const StateVec& x0, const Cov& p0, const InputVec& u0) {
    core_.reset(x0, p0);
    u_ = u0;
    first_ = true;
  }

  /// Job with sample y; the sampling delay argument is ignored (assumed zero).
  constexpr Status update(std::int32_t /*tau_us*/, const OutputVec& y) {
    if (!first_) {
      Discretization<Fmt, kN, kM> d;
      d.phi = design_->phi_h;
      d.gamma = design_->gamma_h;
      d.qd = design_->qd_h;
      core_.predict(d, u_, noise_, design_->q_constant);
    }
    first_ = false;
    return core_.correct_all(y, design_->c, design_->r);
  }

  /// The input applied after this job.
  constexpr void set_applied_input(const InputVec& u) { u_ = u; }
  /// x̂ at the last sample (used as if it were the actuation instant).
  constexpr const StateVec& prediction() const { return core_.state(); }
  /// P after the last correction.
  constexpr const Cov& covariance() const { return core_.covariance(); }
  /// The gain of the last correction.
  constexpr const Gain& gain() const { return core_.gain(); }
  /// The estimator underneath (at the last sample).
  constexpr const Core& core() const { return core_; }

 private:
  const Design* design_;
  NoiseModel noise_;
  Core core_{};
  InputVec u_{};
  bool first_ = true;
};

}  // namespace oneshot
