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
  using Base = KalmanFilterBase<Fmt, Structure, kForm>;

 public:
  using Base::Base;  ///< StandardKalman(design, noise): x̂ = 0, P = P0, u = 0, first sample next.

  /// Estimate x0 with covariance p0 at the first sampling instant.
  constexpr void reset(const typename Base::StateVec& x0, const typename Base::Cov& p0,
                       const typename Base::InputVec& u0) {
    this->core_.reset(x0, p0);
    u_ = u0;
    first_ = true;
  }

  /// Job with sample y; the sampling delay argument is ignored (assumed zero).
  [[nodiscard]] constexpr Status update(std::int32_t /*tau_us*/, const typename Base::OutputVec& y) {
    const auto& d = *this->design_;
    if (!first_) {
      Discretization<Fmt, Base::kN, Base::kM> step;
      step.phi = d.phi_h;
      step.gamma = d.gamma_h;
      step.qd = d.qd_h;
      this->core_.predict(step, u_, this->noise_, d.q_constant);
    }
    first_ = false;
    return this->core_.correct_all(y, d.c, d.r);
  }

  /// The input applied after this job.
  constexpr void set_applied_input(const typename Base::InputVec& u) { u_ = u; }
  /// x̂ at the last sample (used as if it were the actuation instant).
  constexpr const typename Base::StateVec& prediction() const { return this->core_.state(); }

 private:
  typename Base::InputVec u_{};
  bool first_ = true;
};

}  // namespace oneshot
