/// @file plant_structure.hpp
/// @brief Compile-time structure of a plant: dimensions and the patterns of its matrices.
#pragma once

#include <cstddef>

#include "oneshot/pattern.hpp"

namespace oneshot {

/// Structure with no structural entries: correct for any plant, exploits nothing.
template <std::size_t N, std::size_t M, std::size_t P>
struct DenseStructure {
  static constexpr std::size_t kStates = N;   ///< n, state dimension.
  static constexpr std::size_t kInputs = M;   ///< m, input dimension.
  static constexpr std::size_t kOutputs = P;  ///< p, output dimension.
  using PhiPattern = Dense<N, N>;         ///< Φ(t) for every t.
  using GammaPattern = Dense<N, M>;       ///< Γ(t) for every t.
  using QdPattern = Dense<N, N>;          ///< Q_d(t) for every t.
  using ConstantQPattern = Dense<N, N>;   ///< The constant per-step process covariance.
  using OutputPattern = Dense<P, N>;      ///< C.
  using FeedbackPattern = Dense<M, N>;    ///< L.
  using StateFeedforwardPattern = Dense<N, P>;  ///< N_x (x_ref = N_x r).
  using InputFeedforwardPattern = Dense<M, P>;  ///< N_u (u_ref = N_u r).
};

}  // namespace oneshot
