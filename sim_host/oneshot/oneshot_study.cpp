/// @file oneshot_study.cpp
/// @brief The one-shot study (seed 000) under `oneshot-sim oneshot …`: the reference board,
///        approaches A–E, its experiments, the summarizers that merge Table I and kernel
///        shards, and the kernel experiment's report section.
#include <filesystem>
#include <iostream>
#include <memory>

#include "kernel_experiment.hpp"
#include "oneshot/sim/cli_commands.hpp"
#include "oneshot/sim/study_descriptor.hpp"
#include "oneshot/util/output_files.hpp"
#include "oneshot/sim/study_report.hpp"
#include "table1.hpp"

namespace oneshot::sim {

namespace {

struct KernelCliOptions {
  KernelExperimentOptions k;
  CommonOptions common;
  std::string plant;
  std::string shard = "0/1";
  std::string json;
  std::string sample_at = "start";
  std::string actuate_at = "end";
  bool no_plots = false;
};

/// `oneshot-sim oneshot kernel`: the reference loop on a modeled RTOS (issue 22).
void register_kernel_experiment(CLI::App& study) {
  auto c = std::make_shared<KernelCliOptions>();
  c->common.out_dir = "out/kernel";
  CLI::App* cmd = study.add_subcommand(
      "kernel", "the control job as a task on a dsPIC33-class CPU beside other loops and background tasks: "
                "approaches A-E with the schedule's jitter against CPU utilization and the control task's priority");
  cmd->add_option("--plant", c->plant, "plant file (default: the reference board)");
  cmd->add_option("--exectime", c->k.exectime_file,
                  "instruction counts per job: the JSON of `oneshot-sim exectime --target cortex-m0 --json FILE` "
                  "(default: the study's assumed 200-600 us job)");
  cmd->add_option("--variant", c->k.variant, "job variant in that file (default half_table_fixed)");
  cmd->add_option("--mips", c->k.clock_mips, "CPU clock in MIPS (default 40, the reference dsPIC33FJ256MC710)")
      ->check(CLI::Range(0.1, 10000.0));
  cmd->add_option("--utilizations", c->k.utilizations, "CPU utilization grid (default 0.3 0.45 0.6 0.7 0.8 0.85 0.9 0.95)")
      ->check(CLI::Range(0.01, 1.0));
  cmd->add_option("--context-switch-us", c->k.context_switch_us, "context switch (default 2 us)")->check(CLI::Range(0, 1000));
  cmd->add_option("--isr-instructions", c->k.isr_instructions, "actuation timer ISR cost (default 120 instructions)")
      ->check(CLI::Range(1, 1000000));
  cmd->add_option("--duration", c->k.duration_s, "simulated seconds per run (default 20)")->check(CLI::Range(1.0, 100000.0));
  cmd->add_option("--seeds", c->k.seeds, "seeds (default 20)")->check(CLI::Range(2, 1000000));
  cmd->add_option("--seed", c->common.seed, "first seed (default 1)");
  cmd->add_option("--threads", c->common.threads, "worker threads (0: all cores)");
  cmd->add_option("--shard", c->shard, "run part i/N of the sweep (merge with `oneshot-sim merge`)");
  cmd->add_option("--out", c->common.out_dir, "output folder (default out/kernel)");
  cmd->add_option("--json", c->json, "write the summary as JSON to PATH ('-' for standard output)");
  cmd->add_option("--sample-at", c->sample_at,
                  "where the control job reads its input: start (default), end, a fraction of its execution (0.5), "
                  "<n>us of its execution, or <n>instr at the CPU clock");
  cmd->add_option("--actuate-at", c->actuate_at,
                  "where the standard approaches write the output: end (default) or as --sample-at; not before it");
  cmd->add_flag("--no-plots", c->no_plots, "no PNG plots");
  cmd->callback([c] {
    c->common.plots = !c->no_plots;
    c->k.sample_at = engine::cpu::parse_job_point_text(c->sample_at, "--sample-at", c->k.clock_mips);
    c->k.actuate_at = engine::cpu::parse_job_point_text(c->actuate_at, "--actuate-at", c->k.clock_mips);
    c->k.shard = engine::parse_shard(c->shard);
    const auto ctx = SimContext::load(c->plant);
    const nlohmann::json j = run_kernel_experiment(*ctx, c->common, c->k);
    if (c->json != "-" && j.contains("markdown")) std::cout << j["markdown"].get<std::string>();
    if (!c->json.empty()) util::write_json(c->json, j);
  });
}

StudyReportResult kernel_report_section(const StudyReportContext& r) {
  CommonOptions o;
  o.out_dir = r.out_dir;
  o.threads = static_cast<unsigned>(r.threads);
  o.seed = r.seed;
  o.plots = r.plots;
  KernelExperimentOptions k;
  k.seeds = 20;
  // The M0 instruction counts the report measured a moment ago (mcu section), when it ran.
  const std::filesystem::path counts = std::filesystem::path(r.out_dir).parent_path() / "exectime-cortex-m0.json";
  std::error_code ec;
  if (std::filesystem::is_regular_file(counts, ec)) k.exectime_file = counts.string();
  const nlohmann::json j = run_kernel_experiment(*SimContext::reference(), o, k);
  std::string md = "## Study 000 on a modeled RTOS (`oneshot-sim oneshot kernel`)\n\n"
                   "The control job as one task of a dsPIC33-class CPU (fixed-priority preemptive kernel, timer ISR "
                   "for the one-shot actuation) beside six other tasks; the schedule gives the jitter.\n\n" +
                   j.at("markdown").get<std::string>();
  if (r.plots) md += "\n![cost ratio to A against CPU utilization](" + r.rel_dir + "/kernel.png)\n";
  return {md, j};
}

/// design, the experiments (also at the top level) and the kernel experiment.
void add_oneshot_commands(CLI::App* study) {
  register_design_command(*study);
  register_experiment_commands(*study);
  register_kernel_experiment(*study);
}

}  // namespace

StudyDescriptor oneshot_study() {
  // Its Table I and the other experiments open the report (report.cpp); this is the kernel section.
  return {"oneshot",
          "Study 000: the one-shot task model with an embedded Kalman filter on the reference board "
          "(approaches A-E; the same commands are also available at the top level)",
          add_oneshot_commands, {{"table1", table1_outputs}, {"kernel", kernel_outputs}},
          StudyReportSection{"kernel", kernel_report_section}};
}

}  // namespace oneshot::sim
