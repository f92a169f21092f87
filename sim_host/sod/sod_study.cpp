/// @file sod_study.cpp
/// @brief The send-on-delta study (seed 004) under `oneshot-sim sod …`: its commands, the
///        table's merge summarizer and its report section.
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>

#include "oneshot/sim/study_descriptor.hpp"
#include "oneshot/util/output_files.hpp"
#include "oneshot/sim/study_report.hpp"
#include "sod_experiments.hpp"
#include "sod_report.hpp"

namespace oneshot::sim {
namespace {

using sod::StudyOptions;

struct Cli {
  StudyOptions opt;
  std::string json;
  bool no_plots = false;
  std::string shard;
};

void common_options(CLI::App* cmd, Cli& c, bool seeds = true) {
  cmd->add_option("--plant", c.opt.plant_path, "plant file (default: lut_gen/plants/send_on_delta_oscillator.json)")
      ->check(CLI::ExistingFile);
  if (seeds) cmd->add_option("--seeds", c.opt.seeds, "Monte Carlo runs per cell")->check(CLI::Range(2, 1000000))->capture_default_str();
  cmd->add_option("--seed", c.opt.seed, "first seed")->capture_default_str();
  cmd->add_option("--threads", c.opt.threads, "worker threads (0: every core)")->capture_default_str();
  cmd->add_option("--out", c.opt.out_dir, "output folder for CSV files and plots")->capture_default_str();
  cmd->add_option("--json", c.json, "write the result as JSON to PATH ('-' for standard output)");
  cmd->add_flag("--no-plots", c.no_plots, "CSV files only (no gnuplot)");
  cmd->add_option("--delta-y", c.opt.delta_y, "send-on-delta threshold of both nodes")->check(CLI::Range(0.0, 1e6))->capture_default_str();
  cmd->add_option("--mu", c.opt.mu, "design bound: diag P <= mu diag P0")->check(CLI::Range(1.000001, 1e6))->capture_default_str();
  cmd->add_option("--amplitude", c.opt.amplitude, "step input amplitude")->check(CLI::Range(-1e6, 1e6))->capture_default_str();
  cmd->add_option("--steps", c.opt.steps, "samples per run N (T = the plant's period)")->check(CLI::Range(10, 100000000))->capture_default_str();
}

sod::SodModel model_of(Cli& c) {
  if (c.opt.plant_path.empty()) c.opt.plant_path = sod::default_sod_plant_path();
  c.opt.plots = !c.no_plots;
  return sod::load_sod_model(c.opt.plant_path);
}

/// The experiments of the send-on-delta study.
void add_sod_commands(CLI::App* study) {
  {
    auto c = std::make_shared<Cli>();
    CLI::App* cmd = study->add_subcommand("table", "E3 (a)-(c): packets, (2b) sends, losses, e_i and NEES per configuration and loss rate");
    common_options(cmd, *c);
    cmd->add_option("--loss", c->opt.losses, "loss rates xi")->check(CLI::Range(0.0, 0.99))->capture_default_str();
    cmd->add_option("--shard", c->shard, "run part i/N of the sweep (merge with `oneshot-sim merge`)");
    auto inject = std::make_shared<std::string>();
    cmd->add_option("--inject", *inject, "frame faults in every run on links node1/node2, e.g. 'nan:link=node1,rate=0.05' (docs/faults.md)");
    cmd->callback([c, inject] {
      const sod::SodModel m = model_of(*c);
      if (!c->shard.empty()) c->opt.shard = engine::parse_shard(c->shard);
      c->opt.faults = engine::parse_fault_spec(*inject);
      engine::check_fault_targets(c->opt.faults, sod::sod_link_names(), {});
      sod::emit_json(sod::run_table(m, c->opt), c->json);
    });
  }
  {
    auto c = std::make_shared<Cli>();
    CLI::App* cmd = study->add_subcommand("design", "Section 5: P0, dt* per node (null when unbounded), active constraint, dt*·xi");
    common_options(cmd, *c);
    cmd->add_option("--loss", c->opt.design_losses, "loss rates xi")->check(CLI::Range(0.0, 0.99))->capture_default_str();
    cmd->callback([c] {
      const sod::SodModel m = model_of(*c);
      sod::emit_json(sod::run_design(m, c->opt), c->json);
    });
  }
  {
    auto c = std::make_shared<Cli>();
    auto dys = std::make_shared<std::vector<double>>(std::vector<double>{0.1, 0.25, 0.5, 0.75, 1.0});
    CLI::App* cmd = study->add_subcommand("deltat", "E1: mean time between plain-SOD packets (lossless) per delta_y");
    common_options(cmd, *c);
    cmd->add_option("--delta-ys", *dys, "thresholds")->check(CLI::Range(0.0, 1e6))->capture_default_str();
    cmd->callback([c, dys] {
      const sod::SodModel m = model_of(*c);
      sod::emit_json(sod::run_mean_gap(m, c->opt, *dys), c->json);
    });
  }
  {
    auto c = std::make_shared<Cli>();
    auto dys = std::make_shared<std::vector<double>>(std::vector<double>{0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 1.0});
    CLI::App* cmd = study->add_subcommand("grid", "E2: dt* over delta_y x xi (both nodes alike)");
    common_options(cmd, *c);
    cmd->add_option("--delta-ys", *dys, "thresholds")->check(CLI::Range(0.0, 1e6))->capture_default_str();
    cmd->add_option("--loss", c->opt.design_losses, "loss rates xi")->check(CLI::Range(0.0, 0.99))->capture_default_str();
    cmd->callback([c, dys] {
      const sod::SodModel m = model_of(*c);
      sod::emit_json(sod::run_grid(m, c->opt, *dys, c->opt.design_losses), c->json);
    });
  }
  {
    auto c = std::make_shared<Cli>();
    auto dts = std::make_shared<std::vector<double>>(std::vector<double>{0.1, 0.2, 0.5, 1, 2, 5, 10, 20, 30});
    auto losses = std::make_shared<std::vector<double>>(std::vector<double>{0.05, 0.2});
    CLI::App* cmd = study->add_subcommand("curve", "E3 (d): error against packets, dt swept, beside a periodic sender with the same budget");
    common_options(cmd, *c);
    cmd->add_option("--delta-ts", *dts, "time rules dt (s)")->check(CLI::Range(0.0, 1e6))->capture_default_str();
    cmd->add_option("--loss", *losses, "loss rates xi")->check(CLI::Range(0.0, 0.99))->capture_default_str();
    cmd->callback([c, dts, losses] {
      const sod::SodModel m = model_of(*c);
      sod::emit_json(sod::run_curve(m, c->opt, *dts, *losses), c->json);
    });
  }
  {
    auto c = std::make_shared<Cli>();
    auto loss = std::make_shared<double>(0.05);
    CLI::App* cmd = study->add_subcommand("traces", "E4: error over time of (a) and (c), and one run's (2b) sends");
    common_options(cmd, *c);
    cmd->add_option("--loss", *loss, "loss rate xi")->check(CLI::Range(0.0, 0.99))->capture_default_str();
    cmd->callback([c, loss] {
      const sod::SodModel m = model_of(*c);
      sod::emit_json(sod::run_traces(m, c->opt, *loss), c->json);
    });
  }
  {
    auto c = std::make_shared<Cli>();
    CLI::App* cmd = study->add_subcommand("report", "the study's report section alone (design, E1-E4 on the defaults) in OUT/report.md");
    cmd->add_option("--out", c->opt.out_dir, "output folder")->capture_default_str();
    cmd->add_option("--seed", c->opt.seed, "first seed")->capture_default_str();
    cmd->add_option("--threads", c->opt.threads, "worker threads (0: every core)")->capture_default_str();
    cmd->add_option("--json", c->json, "write the section's JSON to PATH ('-' for standard output)");
    cmd->add_flag("--no-plots", c->no_plots, "CSV files only (no gnuplot)");
    cmd->callback([c] {
      util::make_directory(c->opt.out_dir);
      StudyReportContext ctx;
      ctx.out_dir = c->opt.out_dir;
      ctx.rel_dir = ".";
      ctx.threads = c->opt.threads;
      ctx.seed = c->opt.seed;
      ctx.plots = !c->no_plots;
      const StudyReportResult r = sod::report_section(ctx);
      std::ofstream(std::filesystem::path(c->opt.out_dir) / "report.md") << r.markdown;
      sod::emit_json(r.json, c->json);
    });
  }
}

}  // namespace

StudyDescriptor sod_study() {
  return {"sod",
          "Study 004: estimation over a lossy link with send-on-delta and modified send-on-delta sensor nodes",
          add_sod_commands, {{"table", sod::table_outputs}}, StudyReportSection{"sod", sod::report_section}};
}

}  // namespace oneshot::sim
