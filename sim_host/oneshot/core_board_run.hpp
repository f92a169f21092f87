/// @file core_board_run.hpp
/// @brief A closed-loop run of the C++ core's controller on the emulated board, and its
///        run-time-plant variants compiled one number format per source
///        (simulation_runtime_float.cpp, simulation_runtime_double.cpp).
#pragma once

#include <cstdint>
#include <type_traits>

#include "board_loop.hpp"
#include "control_drivers.hpp"
#include "controller_dispatch.hpp"
#include "oneshot/controller.hpp"
#include "simulation.hpp"

namespace oneshot::sim {

/// The board loop with the core controller built from a dispatch's parts (the callback of
/// with_generated_parts / with_runtime_parts).
struct CoreBoardRun {
  const SimContext& ctx;    ///< Plant, design and tables.
  const Scenario& scenario;  ///< The run's scenario.
  std::uint64_t seed;        ///< The run's seed.
  const RunOptions& options;  ///< Approach, format, estimator options.

  /// Builds the controller over the estimator and runs the board loop with it.
  template <typename StructureTag, typename ModelTag, typename Design, typename Estimator>
  RunResult operator()(StructureTag, ModelTag, const Design& design, const Estimator& estimator) const {
    using Ctrl = Controller<typename Design::Format, typename StructureTag::type, Estimator>;
    Ctrl ctrl(design, estimator);
    LocalDriver<Ctrl, ModelTag::value> driver(ctrl);
    return run_board_loop<Design::kStates, Design::kInputs, Design::kOutputs, ModelTag::value>(ctx, scenario, seed,
                                                                                             options, driver);
  }
};

/// simulate() of a run-time plant (dense structure) with the core in Scalar.
template <typename Scalar>
RunResult simulate_runtime(const SimContext& ctx, const Scenario& scenario, std::uint64_t seed,
                           const RunOptions& options) {
  return with_runtime_parts<Scalar>(ctx, options, CoreBoardRun{ctx, scenario, seed, options});
}

// One source per format instantiates it.
extern template RunResult simulate_runtime<float>(const SimContext&, const Scenario&, std::uint64_t, const RunOptions&);
extern template RunResult simulate_runtime<double>(const SimContext&, const Scenario&, std::uint64_t, const RunOptions&);

}  // namespace oneshot::sim
