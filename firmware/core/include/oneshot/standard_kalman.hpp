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

#include "oneshot/kalman_filter_base.hpp"

namespace oneshot {

/// Time-varying Kalman filter on the nominal discrete model (Φ(h), Γ(h)). covariance() is P
/// after the last correction.
template <typename Fmt, typename Structure, CovarianceUpdate kForm = CovarianceUpdate::kSymmetric>
class StandardKalman : public KalmanFilterBase<Fmt, Structure, kForm> {
 public:
  using Base = KalmanFilterBase<Fmt, Structure, kForm>;
  using Base::kM, Base::kN;
  using typename Base::Core, typename Base::Cov, typename Base::Design;
  using typename Base::InputVec, typename Base::OutputVec, typename Base::StateVec;

  /// Filter over `design` (must outlive it).
  constexpr StandardKalman(const Design& design, NoiseModel noise) : Base(design, noise) {
    reset(StateVec{}, design.p0, InputVec{});
  }

  /// Estimate x0 with covariance p0 at the first sampling instant.
  constexpr void reset(const StateVec& x0, const Cov& p0, const InputVec& u0) {
    this->core_.reset(x0, p0);
    u_ = u0;
    first_ = true;
  }

  /// Job with sample y; the sampling delay argument is ignored (assumed zero).
  constexpr Status update(std::int32_t /*tau_us*/, const OutputVec& y) {
    if (!first_) {
      Discretization<Fmt, kN, kM> d;
      d.phi = this->design_->phi_h;
      d.gamma = this->design_->gamma_h;
      d.qd = this->design_->qd_h;
      this->core_.predict(d, u_, this->noise_, this->design_->q_constant);
    }
    first_ = false;
    return this->core_.correct_all(y, this->design_->c, this->design_->r);
  }

  /// The input applied after this job.
  constexpr void set_applied_input(const InputVec& u) { u_ = u; }
  /// x̂ at the last sample (used as if it were the actuation instant).
  constexpr const StateVec& prediction() const { return this->core_.state(); }

 private:
  InputVec u_{};
  bool first_ = true;
};

}  // namespace oneshot
