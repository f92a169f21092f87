/// @file main.cpp
/// @brief oneshot-sim: the host simulator's command line.
#include <CLI/CLI.hpp>
#include <exception>
#include <iostream>

#include "oneshot/sim/cli_commands.hpp"

int main(int argc, char** argv) {
  CLI::App app{"oneshot-sim: host simulator of the one-shot task model with an embedded Kalman filter"};
  app.require_subcommand(1);
  oneshot::sim::register_design_command(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  } catch (const std::exception& e) {
    std::cerr << "oneshot-sim: error: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
