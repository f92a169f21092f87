/// @file trace_sample.hpp
/// @brief One point of a plant's recorded state trace (every engine plant and the studies' own).
#pragma once

#include <cstddef>

#include "oneshot/engine/sim_time.hpp"
#include "oneshot/matrix.hpp"

namespace oneshot::engine {

/// One point of a recorded state trace (values just before the events of instant t).
template <std::size_t N, std::size_t M, std::size_t P>
struct TraceSample {
  SimTime t{0};            ///< Instant.
  Vector<double, N> x;     ///< True state.
  Vector<double, P> r;     ///< Reference in force.
  Vector<double, M> u;     ///< Commanded input in force.
};

}  // namespace oneshot::engine
