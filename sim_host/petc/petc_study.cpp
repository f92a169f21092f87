/// @file petc_study.cpp
/// @brief The petc study (seed 003, issue 15) under `oneshot-sim petc …`: design, table,
///        gpi, traces; the merge summarizers and the report section.
#include <iostream>
#include <memory>
#include <sstream>

#include "oneshot/engine/frame_faults.hpp"
#include "oneshot/sim/study_descriptor.hpp"
#include "oneshot/util/output_files.hpp"
#include "oneshot/sim/pil_link.hpp"
#include "oneshot/sim/study_report.hpp"
#include "petc_exectime.hpp"
#include "petc_experiments.hpp"

namespace oneshot::sim {

namespace {

using namespace petc;

struct Cli {
  PetcOptions design;
  SweepOptions sweep;
  std::string shard = "0/1";
  std::string json;
  std::size_t grid = 7;
  std::uint64_t seed = 1;
  bool no_plots = false;
  std::string inject;
  ExectimeOptions exectime;
};

void add_model_options(CLI::App* cmd, Cli& c) {
  cmd->add_option("--plant", c.design.plant_path, "plant file (default: lut_gen/plants/hdd_numre.json)");
  cmd->add_option("--ratio", c.design.ratio, "MRCI ratio m (default 2)")->check(CLI::Range(1, 16));
  cmd->add_option("--dob-cutoff-hz", c.design.dob_cutoff_hz, "cutoff of the DOB's Q (default 1000 Hz)");
}

void add_sim_options(CLI::App* cmd, Cli& c) {
  add_model_options(cmd, c);
  cmd->add_option("--steps", c.design.steps, "run length K (default 464 = N^TTS)");
  cmd->add_flag("--frozen-noise", c.design.frozen_noise, "printed eq. 13 (w frozen over the interval) instead of W_e(N)");
  cmd->add_flag("--sample-at-update", c.design.sample_at_update, "slow modes sample e at their own update");
  cmd->add_option("--sigma-w", c.design.sigma_w, "sigma_w (default: the plant file's, 3e-4)");
  cmd->add_option("--sigma-v", c.design.sigma_v, "sigma_v (default: the plant file's, 5e-4)");
  cmd->add_option("--out", c.sweep.out_dir, "output folder (default out/petc)");
  cmd->add_flag("--no-plots", c.no_plots, "no PNG plots");
}

void add_sweep_options(CLI::App* cmd, Cli& c) {
  add_sim_options(cmd, c);
  cmd->add_option("--seeds", c.sweep.seeds, "seeds (default 20)");
  cmd->add_option("--seed", c.sweep.first_seed, "first seed (default 1)");
  cmd->add_option("--threads", c.sweep.threads, "worker threads (0: all cores)");
  cmd->add_option("--shard", c.shard, "run part i/N of the sweep (merge with `oneshot-sim merge`)");
  cmd->add_option("--json", c.json, "write the summary as JSON to PATH ('-' for standard output)");
}

void emit(const Cli& c, const nlohmann::json& j) {
  if (!c.json.empty()) util::write_json(c.json, j);
}

std::string design_text(const nlohmann::json& d) {
  std::ostringstream o;
  const auto& p = d.at("plant");
  o << "plant " << p.at("file").get<std::string>() << ": " << p.at("states_plant") << " states + "
    << (p.at("states_augmented").get<int>() - p.at("states_plant").get<int>()) << " disturbance states, T = "
    << p.at("period_us") << " us\n  DC gain " << p.at("dc_gain") << ", relative degree " << p.at("relative_degree")
    << "\n  zeros " << p.at("zeros").dump() << "\n";
  const auto& m = d.at("mrci");
  o << "MRCI at m = " << m.at("ratio") << " (slow if p >= " << m.at("slow_threshold") << "), CS = " << m.at("cs") << "\n";
  for (const auto& s : m.at("slow_modes"))
    o << "  slow: " << s.at("numerator") << "/(z^m - " << s.at("slow_pole") << ")  [pole " << s.at("pole")
      << ", residue " << s.at("residue") << ", phase " << s.at("phase") << "]\n";
  o << "  fast: numerator " << m.at("fast_part").at("numerator").dump() << " / denominator "
    << m.at("fast_part").at("denominator").dump() << " (powers of z, highest first)\n";
  const auto& b = d.at("dob");
  o << "DOB: Q cutoff " << b.at("cutoff_hz") << " Hz, rho = " << b.at("delay") << ", gamma (d->d-dhat) "
    << b.at("gamma_d_to_error") << ", (u->d-dhat) " << b.at("gamma_u_to_error") << "\n";
  return o.str();
}

nlohmann::json design_all(const PetcOptions& o) {
  const PlantFacts plant = load_plant_facts(o.plant_path.empty() ? default_plant_path() : o.plant_path);
  const MrciDesign mrci = brief_mrci(o.ratio);
  const DobDesign dob = design_dob(plant, o.dob_cutoff_hz);
  return design_json(plant, mrci, dob, disturbance_variance(plant, o.steps));
}

StudyReportResult report_section(const StudyReportContext& ctx) {
  PetcOptions o;
  SweepOptions so;
  so.out_dir = ctx.out_dir;
  so.threads = static_cast<unsigned>(ctx.threads);
  so.first_seed = ctx.seed;
  so.plots = ctx.plots;
  const PetcSetup setup = make_setup(o);
  const nlohmann::json design = design_all(o);
  const nlohmann::json table = run_table(setup, so);
  const nlohmann::json gpi = run_gpi(setup, so, 7);
  const nlohmann::json traces = run_traces(setup, ctx.seed, ctx.out_dir, ctx.plots);
  std::ostringstream md;
  md << "## PETC with a non-uniform multi-rate estimator and an interlaced controller (study petc)\n\n"
     << "HDD plant of numre-petc.md (12 states, T = 20 us), K = " << o.steps << " periods, unit step, "
     << so.seeds << " seeds, 95 % intervals (docs/petc.md).\n\n```\n" << design_text(design) << "```\n\n"
     << table_markdown(table) << "\nBest GPI on the " << 7 << "x7 grid: sigma_s = "
     << gpi.at("best").at("sigma_s") << ", sigma_c = " << gpi.at("best").at("sigma_c") << ", GPI "
     << gpi.at("best").at("GPI").at("mean") << ".\n\n";
  if (ctx.plots)
    md << "![GPI](" << ctx.rel_dir << "/gpi.png)\n![case 5](" << ctx.rel_dir << "/trace_case5.png)\n![case 6]("
       << ctx.rel_dir << "/trace_case6.png)\n";
  // One NUMRE arrival on the Cortex-M4F image (QEMU); skipped without the toolchain or QEMU.
  nlohmann::json exectime;
  md << "\n### One NUMRE arrival on the Cortex-M4F (`oneshot-sim petc exectime --json -`)\n\n";
  try {
    exectime = run_exectime(setup, ExectimeOptions{});
    md << exectime_markdown(exectime);
  } catch (const PilError& e) {
    md << "Skipped: " << e.what() << "\n";
    exectime = {{"skipped", e.what()}};
  }
  return {md.str(), {{"design", design}, {"table", table}, {"gpi", gpi}, {"traces", traces}, {"exectime", exectime}}};
}

/// The experiments of the PETC study.
void add_petc_commands(CLI::App* study) {
  auto cli = std::make_shared<Cli>();

  CLI::App* design = study->add_subcommand("design", "MRCI slow modes, fast part, CS; plant DC gain, zeros, relative degree; DOB");
  add_model_options(design, *cli);
  design->add_option("--json", cli->json, "write the design as JSON to PATH ('-' for standard output only)");
  design->callback([cli] {
    const nlohmann::json d = design_all(cli->design);
    if (cli->json != "-") std::cout << design_text(d);
    emit(*cli, d);
  });

  CLI::App* table = study->add_subcommand("table", "cases 1-6 and 6' over seeds: U_c, U_a, C_c, N_E with 95 % intervals and counts");
  add_sweep_options(table, *cli);
  table->add_option("--inject", cli->inject,
                    "frame faults on links sc/ca and restarts of nodes sensor/controller/actuator in every run, e.g. "
                    "'nan:link=sc,rate=0.02; restart:node=controller,at_s=0.004' (docs/faults.md)");
  table->callback([cli] {
    cli->sweep.plots = !cli->no_plots;
    cli->sweep.faults = engine::parse_fault_spec(cli->inject);
    engine::check_fault_targets(cli->sweep.faults, petc_link_names(), petc_node_names());
    cli->sweep.shard = engine::parse_shard(cli->shard);
    const nlohmann::json j = run_table(make_setup(cli->design), cli->sweep);
    if (cli->json != "-" && cli->sweep.shard.whole()) std::cout << table_markdown(j);
    if (cli->json != "-" && j.contains("markdown_faults")) std::cout << "\n" << j.at("markdown_faults").get<std::string>();
    emit(*cli, j);
  });

  CLI::App* gpi = study->add_subcommand("gpi", "GPI surface over sigma_s = delta_s x sigma_c = delta_c (case 4) and its Pareto front");
  add_sweep_options(gpi, *cli);
  gpi->add_option("--grid", cli->grid, "grid points per axis (default 7)");
  gpi->callback([cli] {
    cli->sweep.plots = !cli->no_plots;
    cli->sweep.shard = engine::parse_shard(cli->shard);
    const nlohmann::json j = run_gpi(make_setup(cli->design), cli->sweep, cli->grid);
    if (cli->json != "-" && cli->sweep.shard.whole())
      std::cout << "best GPI: " << j.at("best").dump() << "\n";
    emit(*cli, j);
  });

  CLI::App* traces = study->add_subcommand("traces", "d, d_hat and N against time for cases 4, 5, 6, 6' (one seed)");
  add_sim_options(traces, *cli);
  traces->add_option("--seed", cli->seed, "seed (default 1)");
  traces->add_option("--json", cli->json, "write the summary as JSON to PATH ('-' for standard output)");
  traces->callback([cli] {
    const nlohmann::json j = run_traces(make_setup(cli->design), cli->seed, cli->sweep.out_dir, !cli->no_plots);
    if (cli->json != "-") std::cout << j.dump(2) << "\n";
    emit(*cli, j);
  });

  CLI::App* exectime = study->add_subcommand(
      "exectime", "instructions of one NUMRE arrival by N on the Cortex-M4F image (QEMU), beside its multiply-adds; "
                  "bit-identity with the host float node; flash, RAM, stack");
  add_model_options(exectime, *cli);
  exectime->add_option("--steps", cli->design.steps, "run length K of the traces that give y and N (default 464)");
  exectime->add_flag("--frozen-noise", cli->design.frozen_noise, "printed eq. 13 instead of W_e(N)");
  exectime->add_flag("--sample-at-update", cli->design.sample_at_update, "slow modes sample e at their own update");
  exectime->add_option("--sigma-w", cli->design.sigma_w, "sigma_w (default: the plant file's, 3e-4)");
  exectime->add_option("--sigma-v", cli->design.sigma_v, "sigma_v (default: the plant file's, 5e-4)");
  exectime->add_option("--case", cli->exectime.case_name, "case whose measurements give y (3, 4, 5; default 4); N comes from cases 3-5");
  exectime->add_option("--seed", cli->exectime.seed, "seed of that trace (default 1)");
  exectime->add_option("--multiplicity", cli->exectime.extra, "more multiplicities N to measure (besides 1, median, max)");
  exectime->add_option("--firmware-dir", cli->exectime.firmware_dir, "build tree holding firmware-cortex-m4f/ (default: this build's)");
  exectime->add_option("--json", cli->json, "write the result as JSON to PATH ('-' for standard output)");
  exectime->callback([cli] {
    const nlohmann::json j = run_exectime(make_setup(cli->design), cli->exectime);
    if (cli->json != "-") std::cout << exectime_markdown(j);
    emit(*cli, j);
  });
}

}  // namespace

StudyDescriptor petc_study() {
  return {"petc",
          "Study 003: periodic event-triggered control of an HDD servo with a non-uniform multi-rate "
          "estimator (NUMRE), packets of future inputs and an interlaced controller (MRCI)",
          add_petc_commands, {{"table", table_outputs}, {"gpi", gpi_outputs}},
          StudyReportSection{"petc", report_section}};
}

}  // namespace oneshot::sim
