/// @file oneshot_study.cpp
/// @brief The one-shot study (seed 000) under `oneshot-sim oneshot …`: the reference board,
///        approaches A–E, its experiments, and the summarizer that merges Table I shards.
#include "oneshot/engine/sweep_registry.hpp"
#include "oneshot/sim/cli_commands.hpp"
#include "table1.hpp"

namespace oneshot::sim {

void register_oneshot_study(CLI::App& app) {
  CLI::App* study = app.add_subcommand(
      "oneshot", "Study 000: the one-shot task model with an embedded Kalman filter on the reference board "
                 "(approaches A-E; the same commands are also available at the top level)");
  study->require_subcommand(1);
  register_design_command(*study);
  register_experiment_commands(*study);
  engine::register_summarizer("oneshot", "table1", [](const engine::SweepResults& r, const std::string& out, bool plots) {
    return table1_outputs(r, out, plots);
  });
}

}  // namespace oneshot::sim
