/// @file core_board_run.hpp
/// @brief A closed-loop run of the C++ core's controller on the emulated board and the replay
///        of a run's jobs through it, with their run-time-plant variants compiled one number
///        format per source (simulation_runtime_float.cpp, simulation_runtime_double.cpp: the
///        run and the replay of one format share their instantiations).
#pragma once

#include <cstdint>
#include <functional>
#include <type_traits>
#include <vector>

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

/// Replays recorded jobs through a fresh controller built from a dispatch's parts (the callback
/// of with_generated_parts / with_runtime_parts): with_job_replay().
struct CoreJobReplay {
  const std::vector<JobRecord>& jobs;                                   ///< The run's jobs.
  const std::function<void(const std::function<void()>&)>& use;  ///< Called with the replay.

  /// Converts the inputs once (as the ADC driver hands them over), then hands `use` a replay
  /// of every job from the initial controller.
  template <typename StructureTag, typename ModelTag, typename Design, typename Estimator>
  void operator()(StructureTag, ModelTag, const Design& design, const Estimator& estimator) const {
    using Ctrl = Controller<typename Design::Format, typename StructureTag::type, Estimator>;
    using St = typename Design::Format::State;
    constexpr std::size_t kP = Design::kOutputs;
    Ctrl ctrl(design, estimator);
    const auto initial = ctrl;
    std::vector<typename Ctrl::OutputVec> ys(jobs.size());
    std::vector<typename Ctrl::OutputVec> rs(jobs.size());
    for (std::size_t k = 0; k < jobs.size(); ++k)
      for (std::size_t o = 0; o < kP; ++o) {
        ys[k][o] = output_of_code(design.sensor, o, jobs[k].y_code);
        rs[k][o] = output_of_code(design.sensor, o, jobs[k].setpoint_code);
      }
    std::int32_t codes[Design::kInputs] = {};
    St sink{};
    use([&]() {
      ctrl = initial;
      // Timing only: the statuses of these jobs are those of the simulated run, checked there.
      for (std::size_t k = 0; k < jobs.size(); ++k) (void)ctrl.job(jobs[k].tau_us, ys[k], rs[k], codes);
      sink = ctrl.estimator().prediction()[0];
    });
    static_cast<void>(sink);
  }
};

/// simulate() of a run-time plant (dense structure) with the core in Scalar.
template <typename Scalar>
RunResult simulate_runtime(const SimContext& ctx, const Scenario& scenario, std::uint64_t seed,
                           const RunOptions& options) {
  return with_runtime_parts<Scalar>(ctx, options, CoreBoardRun{ctx, scenario, seed, options});
}

/// with_job_replay() of a run-time plant (dense structure) with the core in Scalar.
template <typename Scalar>
void replay_runtime(const SimContext& ctx, const RunOptions& options, const std::vector<JobRecord>& jobs,
                    const std::function<void(const std::function<void()>&)>& use) {
  with_runtime_parts<Scalar>(ctx, options, CoreJobReplay{jobs, use});
}

// One source per format instantiates them.
extern template RunResult simulate_runtime<float>(const SimContext&, const Scenario&, std::uint64_t, const RunOptions&);
extern template RunResult simulate_runtime<double>(const SimContext&, const Scenario&, std::uint64_t, const RunOptions&);
extern template void replay_runtime<float>(const SimContext&, const RunOptions&, const std::vector<JobRecord>&,
                                           const std::function<void(const std::function<void()>&)>&);
extern template void replay_runtime<double>(const SimContext&, const RunOptions&, const std::vector<JobRecord>&,
                                            const std::function<void(const std::function<void()>&)>&);

}  // namespace oneshot::sim
