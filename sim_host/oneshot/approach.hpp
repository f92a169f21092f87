/// @file approach.hpp
/// @brief The five approaches of the brief's Table I (A–E).
#pragma once

#include <array>
#include <cstdint>
#include <string>

#include "oneshot/app/control_task.hpp"

namespace oneshot::sim {

/// Approach of Table I.
enum class Approach : std::uint8_t {
  kA,  ///< Kalman with standard controller, no jitter (reference).
  kB,  ///< Half Kalman with one-shot controller.
  kC,  ///< Complete Kalman with one-shot controller.
  kD,  ///< Kalman with standard controller, with jitter.
  kE,  ///< Standard controller without Kalman filter (deadbeat observer), with jitter.
};

/// Every approach, in table order.
inline constexpr std::array<Approach, 5> kAllApproaches = {Approach::kA, Approach::kB, Approach::kC, Approach::kD,
                                                           Approach::kE};

/// The estimator an approach runs.
enum class EstimatorKind : std::uint8_t { kStandardKalman, kHalfKalman, kCompleteKalman, kDeadbeat };

/// Static description of an approach.
struct ApproachInfo {
  char letter;                  ///< 'A' … 'E'.
  const char* description;      ///< Human description.
  app::TaskModel model;         ///< Task model.
  EstimatorKind estimator;      ///< Estimator.
  bool jitter;                  ///< Whether the scenario's jitter applies.
};

/// Description of `a`.
constexpr ApproachInfo info(Approach a) {
  switch (a) {
    case Approach::kA:
      return {'A', "Kalman, standard controller, no jitter", app::TaskModel::kStandard, EstimatorKind::kStandardKalman, false};
    case Approach::kB:
      return {'B', "half Kalman, one-shot controller", app::TaskModel::kOneShot, EstimatorKind::kHalfKalman, true};
    case Approach::kC:
      return {'C', "complete Kalman, one-shot controller", app::TaskModel::kOneShot, EstimatorKind::kCompleteKalman, true};
    case Approach::kD:
      return {'D', "Kalman, standard controller, jitter", app::TaskModel::kStandard, EstimatorKind::kStandardKalman, true};
    case Approach::kE:
      return {'E', "standard controller, no Kalman, jitter", app::TaskModel::kStandard, EstimatorKind::kDeadbeat, true};
  }
  return {'?', "", app::TaskModel::kStandard, EstimatorKind::kStandardKalman, false};
}

/// Approach of letter 'A' … 'E' (case-insensitive); std::invalid_argument otherwise.
Approach parse_approach(const std::string& letter);

}  // namespace oneshot::sim
