/// @file cli_design.cpp
/// @brief `oneshot-sim design`.
#include <iostream>
#include <memory>

#include "oneshot/design/controller_synthesis.hpp"
#include "oneshot/design/design_report.hpp"
#include "oneshot/design/plant_description.hpp"
#include "oneshot/sim/cli_commands.hpp"
#include "oneshot/util/output_files.hpp"

namespace oneshot::sim {

void register_design_command(CLI::App& app) {
  struct Options {
    std::string plant;
    std::string json;
  };
  auto opt = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand("design", "Print the design (Phi(h), Gamma(h), LQR gain L, Kalman gain) of a plant");
  cmd->add_option("--plant", opt->plant, "plant description JSON (default: the built-in reference board)");
  cmd->add_option("--json", opt->json, "also write the design as JSON to PATH ('-' for standard output only)");
  cmd->callback([opt]() {
    const design::PlantDescription plant =
        opt->plant.empty() ? design::reference_plant() : design::load_plant_file(opt->plant);
    const design::DesignResult result = design::synthesize(plant);
    const nlohmann::json j = design::design_json(plant, result);
    if (opt->json == "-") {
      util::write_json("-", j);
      return;
    }
    design::print_design(std::cout, plant, result);
    if (!opt->json.empty()) util::write_json(opt->json, j);
  });
}

}  // namespace oneshot::sim
