/// @file half_kalman.hpp
/// @brief Half Kalman filter inside the one-shot task model.
///
/// Job k samples y at t_s,k = t_k − τ_k, between actuations t_{k−1} and t_k; the state
/// kept between jobs is the prediction at the last actuation instant. update(τ_k, y):
///   x̂⁻_s,k = Φ(h−τ_k) x̂⁻_{k−1} + Γ(h−τ_k) u_{k−1},  P⁻_s,k = Φ P⁻_{k−1} Φᵀ + Q
///   correct with y (kalman_estimator.hpp)
///   x̂⁻_k   = Φ(τ_k) x̂_s,k + Γ(τ_k) u_{k−1},        P⁻_k = Φ P_s,k Φᵀ + Q
/// and u_k = −L x̂⁻_k is applied at t_k (set_applied_input()). Only predictions to the
/// actuation instant are stored, so Φ is needed at two arguments per job. Built on
/// KalmanEstimator: two predict(Δt) and one correction of every output.
#pragma once

#include <cstddef>
#include <cstdint>

#include "oneshot/kalman_filter_base.hpp"

namespace oneshot {

/// Half Kalman filter; Disc is a GenericDiscretizer or TableDiscretizer. covariance() is P⁻_k
/// (at the next actuation instant).
template <typename Fmt, typename Structure, typename Disc,
          CovarianceUpdate kForm = CovarianceUpdate::kSymmetric>
class HalfKalman : public DiscretizedFilterBase<Fmt, Structure, Disc, kForm> {
  using Base = DiscretizedFilterBase<Fmt, Structure, Disc, kForm>;

 public:
  using Base::Base;  ///< HalfKalman(design, disc, noise): x̂⁻ = 0, P⁻ = P0, u = 0.

  /// Estimate x0 with covariance p0 at an actuation instant, input u0 applied there.
  constexpr void reset(const typename Base::StateVec& x0, const typename Base::Cov& p0,
                       const typename Base::InputVec& u0) {
    this->core_.reset(x0, p0);
    u_ = u0;
  }

  /// Job with sample y taken tau_us before the next actuation instant (bounded to
  /// ±kMaxTauUs first: kClamped beyond).
  [[nodiscard]] constexpr Status update(std::int32_t tau_us, const typename Base::OutputVec& y) {
    Status status = this->job_tau(tau_us);
    const auto& d = *this->design_;
    status = worst_of(status, this->core_.predict(*this->disc_, d.period_us - tau_us, u_, this->noise_, d.q_constant));
    status = worst_of(status, this->core_.correct_all(y, d.c, d.r));
    status = worst_of(status, this->core_.predict(*this->disc_, tau_us, u_, this->noise_, d.q_constant));
    return status;
  }

  /// A period without a job (its sample lost or refused): from the last actuation instant
  /// to the next one, x̂⁻ ← Φ(h) x̂⁻ + Γ(h) u, P⁻ ← Φ(h) P⁻ Φ(h)ᵀ + Q, u the input applied
  /// there (set_applied_input()).
  [[nodiscard]] constexpr Status skip_period() {
    return this->core_.predict(*this->disc_, this->design_->period_us, u_, this->noise_, this->design_->q_constant);
  }
  /// The input applied at the actuation instant the last update predicted to.
  constexpr void set_applied_input(const typename Base::InputVec& u) { u_ = u; }
  /// x̂⁻_k: the estimate at the next actuation instant.
  constexpr const typename Base::StateVec& prediction() const { return this->core_.state(); }

 private:
  typename Base::InputVec u_{};
};

}  // namespace oneshot
