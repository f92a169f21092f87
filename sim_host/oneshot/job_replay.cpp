/// @file job_replay.cpp
/// @brief with_job_replay() (simulation.hpp): a run's jobs replayed through a fresh core
///        controller, for timing the job alone.
#include <cstdint>
#include <functional>
#include <type_traits>
#include <vector>

#include "controller_dispatch.hpp"
#include "oneshot/controller.hpp"
#include "simulation.hpp"

namespace oneshot::sim {

void with_job_replay(const SimContext& ctx, const RunOptions& options, const std::vector<JobRecord>& jobs,
                     const std::function<void(const std::function<void()>&)>& use) {
  with_controller_parts(ctx, options, [&](auto structure, auto, const auto& design, const auto& estimator) {
    using Design = std::decay_t<decltype(design)>;
    using Ctrl = Controller<typename Design::Format, typename decltype(structure)::type, std::decay_t<decltype(estimator)>>;
    using St = typename Design::Format::State;
    constexpr std::size_t kP = Design::kOutputs;
    Ctrl ctrl(design, estimator);
    const auto initial = ctrl;
    // Inputs converted once, as the ADC driver would hand them over.
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
  });
}

}  // namespace oneshot::sim
