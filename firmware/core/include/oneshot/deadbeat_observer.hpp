/// @file deadbeat_observer.hpp
/// @brief State observer of the standard controller without Kalman filter (approach E).
///
/// Current-form observer on the nominal model with a constant gain K_db placing every
/// eigenvalue of (I − K_db C)Φ(h) at zero (designed on the host):
///   x̄ = Φ(h) x̂ + Γ(h) u,   x̂ = x̄ + K_db (y − C x̄).
/// It reconstructs the state exactly after n noise-free samples but does not filter
/// measurement noise: the "no Kalman" baseline.
#pragma once

#include <cstddef>
#include <cstdint>

#include "oneshot/controller_design.hpp"
#include "oneshot/innovation.hpp"
#include "oneshot/one_shot_predictor.hpp"

namespace oneshot {

/// Deadbeat current observer on the nominal discrete model.
template <typename Fmt, typename Structure>
class DeadbeatObserver : public StructureTypes<Fmt, Structure> {
  using Types = StructureTypes<Fmt, Structure>;

 public:
  using Cov = Matrix<typename Fmt::Covariance, Types::kN, Types::kN>;  ///< P (not kept).

  /// Observer over `design` (must outlive it).
  constexpr explicit DeadbeatObserver(const typename Types::Design& design) : design_(&design) {}

  /// Estimate x0 at the first sampling instant (covariance ignored).
  constexpr void reset(const typename Types::StateVec& x0, const Cov& /*p0*/, const typename Types::InputVec& u0) {
    x_ = x0;
    u_ = u0;
    first_ = true;
  }

  /// Job with sample y; the sampling delay argument is ignored (assumed zero).
  [[nodiscard]] constexpr Status update(std::int32_t /*tau_us*/, const typename Types::OutputVec& y) {
    if (!first_) {
      x_ = affine<typename Fmt::State, typename Structure::PhiPattern, typename Structure::GammaPattern>(
          design_->phi_h, x_, design_->gamma_h, u_);
    }
    first_ = false;
    add_gain_times<Fmt>(x_, design_->deadbeat_gain,
                        innovation<Fmt, typename Structure::OutputPattern>(y, design_->c, x_));
    return Status::kOk;
  }

  /// The input applied after this job.
  constexpr void set_applied_input(const typename Types::InputVec& u) { u_ = u; }
  /// x̂ at the last sample.
  constexpr const typename Types::StateVec& prediction() const { return x_; }

 private:
  const typename Types::Design* design_;
  typename Types::StateVec x_{};
  typename Types::InputVec u_{};
  bool first_ = true;
};

}  // namespace oneshot
