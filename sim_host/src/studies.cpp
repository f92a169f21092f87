/// @file studies.cpp
/// @brief The registration point of the studies: one line per study.
///
/// A study lives in its own folder sim_host/<study>/ (its plant and scenario files, its
/// approaches, experiments and plots), is built into oneshot-sim by sim_host/CMakeLists.txt
/// (ONESHOT_STUDIES), and registers its commands under `oneshot-sim <study> <experiment>`
/// here, together with the summarizers that let `oneshot-sim merge` finish its sweeps.
/// The engine (sim_host/engine/) knows no study. Upcoming: ncs (seed 001), dropping
/// (seed 002), petc (seed 003), sod (seed 004).
#include "oneshot/sim/cli_commands.hpp"

namespace oneshot::sim {

void register_studies(CLI::App& app) {
  register_oneshot_study(app);  // sim_host/oneshot/: seed 000, the one-shot task model
  register_ncs_study(app);       // sim_host/ncs/:      networked actuation sync (issue 12)
  register_dropping_study(app);  // sim_host/dropping/: over-delay dropping Kalman (issue 13)
  register_sod_study(app);       // sim_host/sod/:      send-on-delta estimation (issue 14)
  register_petc_study(app);      // sim_host/petc/:     NUMRE periodic event-triggered control (issue 15)
  register_kernel_study(app);    // sim_host/kernel/:   CPUs, schedulers, response-time analysis (issue 22)
}

}  // namespace oneshot::sim
