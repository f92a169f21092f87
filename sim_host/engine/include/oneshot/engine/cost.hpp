/// @file cost.hpp
/// @brief The control cost a plant accumulates along its true trajectory.
#pragma once

namespace oneshot::engine {

/// J = ∫ eᵀQ1c e + ũᵀQ2c ũ dt (continuous plants) or Σ per step (discrete plants), split
/// by origin; e = x − x_ref, ũ = u − u_ref.
struct CostBreakdown {
  double state = 0;  ///< State term along the deterministic (noise-free between events) trajectory.
  double noise = 0;  ///< Expected contribution of the noise path inside intervals (continuous plants).
  double input = 0;  ///< Input term.
  /// The total cost J.
  double total() const { return state + noise + input; }
};

}  // namespace oneshot::engine
