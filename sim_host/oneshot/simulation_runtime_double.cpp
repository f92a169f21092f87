/// @file simulation_runtime_double.cpp
/// @brief simulate() and with_job_replay() of run-time plants in double (core_board_run.hpp): one
///        format per source, so the dimension x estimator instantiations compile in parallel.
#include "core_board_run.hpp"

namespace oneshot::sim {

template RunResult simulate_runtime<double>(const SimContext&, const Scenario&, std::uint64_t, const RunOptions&);
template void replay_runtime<double>(const SimContext&, const RunOptions&, const std::vector<JobRecord>&,
                                  const std::function<void(const std::function<void()>&)>&);

}  // namespace oneshot::sim
