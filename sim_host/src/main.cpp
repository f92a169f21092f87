/// @file main.cpp
/// @brief oneshot-sim: the host simulator's command line.
#include <CLI/CLI.hpp>
#include <csignal>
#include <exception>
#include <iostream>
#include <string>

#include "oneshot/util/termination_cleanup.hpp"
#include "oneshot/sim/cli_commands.hpp"

int main(int argc, char** argv) {
  // Interrupted runs end their child processes and remove temporary files; a child that
  // died must give an error on write, not kill us with SIGPIPE.
  oneshot::util::install_termination_handlers();
  std::signal(SIGPIPE, SIG_IGN);
  CLI::App app{"oneshot-sim: discrete-event simulator of control loops on small MCUs and over networks.\n"
               "Studies: oneshot-sim <study> <experiment> (oneshot-sim <study> --help); the one-shot study's\n"
               "experiments are also top-level commands (design, noise, jitter, gain, table1, ...)"};
  app.require_subcommand(1);
  oneshot::sim::register_design_command(app);
  oneshot::sim::register_experiment_commands(app);
  oneshot::sim::register_studies(app);
  oneshot::sim::register_merge_command(app);
  const auto known = [&](const std::string& name) {
    for (const CLI::App* sub : app.get_subcommands({})) {
      if (sub->get_name() == name) return true;
    }
    return false;
  };
  if (argc > 1 && argv[1][0] != '-' && !known(argv[1])) {
    std::cerr << "oneshot-sim: unknown command '" << argv[1] << "' (see oneshot-sim --help)\n";
    return 2;
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  } catch (const std::exception& e) {
    std::cerr << "oneshot-sim: error: " << e.what() << "\n";
    return 1;
  }
  std::cout.flush();
  if (!std::cout) {
    std::cerr << "oneshot-sim: error: standard output: write failed\n";
    return 1;
  }
  return 0;
}
