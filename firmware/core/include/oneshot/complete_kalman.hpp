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
/// Built on KalmanEstimator: the prediction is predict_across() over an input history
/// holding u_{k−1} from the sample and u_k from t_k; Γ(a) is the Γ(τ_k) of the previous
/// job's actuation prediction. Φ is evaluated at three arguments per job (a+b up to 2h,
/// b, τ_{k+1}). The reset state is an estimate at an actuation instant (a = 0, as for the
/// half filter), so the first job adds no constant Q for interval a: both filters then
/// produce the same estimates.
#pragma once

#include <cstddef>
#include <cstdint>

#include "oneshot/kalman_filter_base.hpp"

namespace oneshot {

/// Complete Kalman filter; Disc is a GenericDiscretizer or TableDiscretizer. covariance() is
/// P_s,k (corrected at the last sample).
template <typename Fmt, typename Structure, typename Disc,
          CovarianceUpdate kForm = CovarianceUpdate::kSymmetric>
class CompleteKalman : public DiscretizedFilterBase<Fmt, Structure, Disc, kForm> {
  using Base = DiscretizedFilterBase<Fmt, Structure, Disc, kForm>;

 public:
  /// Filter over `design` and `disc` (both must outlive it).
  constexpr CompleteKalman(const typename Base::Design& design, const Disc& disc, NoiseModel noise)
      : Base(design, disc, noise) {
    reset({}, design.p0, {});
  }

  /// Estimate x0 with covariance p0 at an actuation instant, input u0 applied there
  /// (treated as a sample with τ = 0: a zero-length segment of u0, then u0).
  constexpr void reset(const typename Base::StateVec& x0, const typename Base::Cov& p0,
                       const typename Base::InputVec& u0) {
    this->core_.reset(x0, p0);
    x_ = x0;
    inputs_.reset(u0);
    (void)inputs_.push(0, u0);  // cannot fail: one change after a reset
    gamma_a_ = {};
    tau_prev_us_ = 0;
    first_job_ = true;
  }

  /// Job with sample y taken tau_us before the next actuation instant (bounded to
  /// ±kMaxTauUs first: kClamped beyond).
  [[nodiscard]] constexpr Status update(std::int32_t tau_us, const typename Base::OutputVec& y) {
    Status status = this->job_tau(tau_us);
    const auto& d = *this->design_;
    const std::int32_t b_us = d.period_us - tau_us;
    if (inputs_.size() == 1) (void)inputs_.push(tau_prev_us_, inputs_.latest());  // no new input at t_k; cannot fail
    status = worst_of(status, this->core_.predict_across(*this->disc_, b_us + tau_prev_us_, inputs_, this->noise_,
                                                         d.q_constant, &gamma_a_, !first_job_));
    status = worst_of(status, this->core_.correct_all(y, d.c, d.r));
    typename Disc::Triple c{NoInit{}};
    status = worst_of(status, this->disc_->discretize(tau_us, c, WithQd::kNo));
    x_ = predict_state<Fmt, Structure>(c, this->core_.state(), inputs_.latest());
    gamma_a_ = c.gamma;
    tau_prev_us_ = tau_us < 0 ? 0 : tau_us;
    inputs_.reset(inputs_.latest());  // u_k is active at the sample
    first_job_ = false;
    return status;
  }

  /// The input applied at the actuation instant the last update predicted to.
  constexpr void set_applied_input(const typename Base::InputVec& u) {
    if (inputs_.size() > 1) inputs_.reset(inputs_.latest());  // a second call: the previous input came before
    (void)inputs_.push(tau_prev_us_, u);  // cannot fail: one change after a reset
  }
  /// x̂_k: the estimate at the next actuation instant.
  constexpr const typename Base::StateVec& prediction() const { return x_; }

 private:
  typename Base::StateVec x_{};                              // prediction to the next actuation
  InputHistory<typename Fmt::Input, Base::kM, 2> inputs_{};  // u_{k−1} from the sample, u_k from t_k
  typename Base::Core::InputGain gamma_a_{};                 // Γ(τ_k)
  std::int32_t tau_prev_us_ = 0;
  bool first_job_ = true;
};

}  // namespace oneshot
