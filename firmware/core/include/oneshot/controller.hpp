/// @file controller.hpp
/// @brief One control job: estimator update, control law, actuator quantisation.
///
/// The estimator decides the task model: HalfKalman / CompleteKalman predict to the
/// actuation instant (one-shot), StandardKalman / DeadbeatObserver assume zero delay.
#pragma once

#include <cstddef>
#include <cstdint>

#include "oneshot/control_law.hpp"
#include "oneshot/status.hpp"

namespace oneshot {

/// Control job around an estimator (HalfKalman, CompleteKalman, StandardKalman, DeadbeatObserver).
template <typename Fmt, typename Structure, typename Estimator>
class Controller : public StructureTypes<Fmt, Structure> {
  using Types = StructureTypes<Fmt, Structure>;

 public:
  using CovScalar = typename Fmt::Covariance;  ///< Scalar of P (the fixed-point checks).
  using EstimatorType = Estimator;             ///< The estimator it drives.

  /// Controller over `design` and an estimator built on the same design.
  constexpr Controller(const typename Types::Design& design, const Estimator& estimator)
      : design_(&design), estimator_(estimator) {}

  /// Job: sample y taken tau_us before the actuation instant it prepares, set-point r.
  /// Writes the actuator codes to `codes` and returns the estimator's status.
  [[nodiscard]] constexpr Status job(std::int32_t tau_us, const typename Types::OutputVec& y,
                                     const typename Types::OutputVec& setpoint, std::int32_t (&codes)[Types::kM]) {
    const Status status = estimator_.update(tau_us, y);
    const typename Types::InputVec u = control_law<Fmt, Structure>(*design_, estimator_.prediction(), setpoint);
    for (std::size_t j = 0; j < Types::kM; ++j) {
      codes[j] = quantize_input(design_->actuator, j, u[j]);
      applied_[j] = input_of_code(design_->actuator, j, codes[j]);
    }
    estimator_.set_applied_input(applied_);
    return status;
  }

  /// The estimator (for its prediction, covariance and gain).
  constexpr const Estimator& estimator() const { return estimator_; }
  /// Mutable estimator access (reset).
  constexpr Estimator& estimator() { return estimator_; }
  /// The design constants.
  constexpr const typename Types::Design& design() const { return *design_; }
  /// The input realised by the last job's codes.
  constexpr const typename Types::InputVec& applied_input() const { return applied_; }

 private:
  const typename Types::Design* design_;
  Estimator estimator_;
  typename Types::InputVec applied_{};
};

}  // namespace oneshot
