/// @file cli_experiments.cpp
/// @brief Subcommands noise, jitter, gain, table1, exectime, run, benchmark and report.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <fstream>
#include <iostream>
#include <map>
#include <memory>
#include <sstream>

#include "cli_common.hpp"
#include "oneshot/sim/cli_commands.hpp"
#include "oneshot_experiments.hpp"
#include "table1_analytic.hpp"
#include "oneshot/util/output_files.hpp"
#include "oneshot/util/parallel.hpp"
#include "oneshot/sim/pil_link.hpp"

namespace oneshot::sim {

using namespace cli;  // the common options (cli_common.hpp)

void register_experiment_commands(CLI::App& app) {
  {
    auto duration = std::make_shared<double>(5.0);
    CLI::App* cmd = add_experiment(app, "noise", "Experiment 1: noisy measured v1 beside the estimated states", "out/noise",
                                   [duration](const CliCommon& c, const SimContext& ctx) {
                                     emit(c, run_noise_experiment(ctx, c.resolve(), *duration));
                                   });
    cmd->add_option("--duration", *duration, "simulated seconds")->check(finite_in(0.1, 3600.0))->capture_default_str();
  }
  {
    auto duration = std::make_shared<double>(6.0);
    auto jitter = std::make_shared<std::int32_t>(20'000);
    CLI::App* cmd = add_experiment(app, "jitter", "Experiment 2: one-shot + half Kalman against standard controllers under jitter",
                                   "out/jitter", [duration, jitter](const CliCommon& c, const SimContext& ctx) {
                                     emit(c, run_jitter_experiment(ctx, c.resolve(), *duration, *jitter));
                                   });
    cmd->add_option("--duration", *duration, "simulated seconds")->check(finite_in(0.1, 3600.0))->capture_default_str();
    cmd->add_option("--jitter-us", *jitter, "largest release delay of the job (us)")->check(CLI::Range(0, 10'000'000))->capture_default_str();
  }
  {
    auto duration = std::make_shared<double>(3.0);
    auto p0 = std::make_shared<double>(100.0);
    CLI::App* cmd = add_experiment(app, "gain", "Experiment 3: first Kalman gain element over time", "out/gain",
                                   [duration, p0](const CliCommon& c, const SimContext& ctx) {
                                     emit(c, run_gain_experiment(ctx, c.resolve(), *duration, *p0));
                                   });
    cmd->add_option("--duration", *duration, "simulated seconds")->check(finite_in(0.1, 3600.0))->capture_default_str();
    cmd->add_option("--p0-scale", *p0, "initial covariance as a multiple of the steady state")->check(finite_in(0.0, 1e12, true))->capture_default_str();
  }
  {
    auto c = std::make_shared<CliCommon>();
    auto seeds = std::make_shared<std::size_t>(20);
    auto file = std::make_shared<std::string>();
    CLI::App* cmd = app.add_subcommand("table1", "Experiment 4: approaches A-E on the scenarios with 95 % confidence intervals");
    add_common(cmd, *c, "out/table1");
    cmd->add_option("--seeds", *seeds, "seeds per scenario")->check(CLI::Range(2, 100000))->capture_default_str();
    cmd->add_option("--scenarios", *file, "scenario file (default: the ten built-in scenarios)")->check(CLI::ExistingFile);
    auto shard = std::make_shared<std::string>("0/1");
    cmd->add_option("--shard", *shard,
                    "run only part i/N of the sweep (0 <= i < N) and write OUT/table1.shard-i-of-N.json; "
                    "`oneshot-sim merge` joins the shards into the same result as one run")
        ->capture_default_str();
    auto analytic = std::make_shared<bool>(false);
    cmd->add_flag("--analytic", *analytic,
                  "the linear board (PWM average, ADC unquantized): exact expected cost per timing draw beside its "
                  "Monte Carlo and the emulated board's cost; OUT/table1_analytic.md");
    cmd->callback([c, seeds, file, shard, analytic]() {
      const auto ctx = SimContext::load(c->plant);
      const engine::Shard part = engine::parse_shard(*shard);
      double wall = 0;
      const CommonOptions o = c->resolve();
      if (*analytic) {
        if (!part.whole()) throw std::invalid_argument("--analytic runs the whole table: no --shard");
        const nlohmann::json j = run_table1_analytic(*ctx, o, scenarios_from(*file), *seeds, &wall);
        write_timing(o, "table1_analytic", wall);
        if (c->json != "-") {
          std::cout << j["markdown"].get<std::string>();
          std::cout << "wall time " << wall << " s on " << util::worker_count(o.threads) << " threads\n";
        }
        emit(*c, j);
        return;
      }
      const nlohmann::json j = run_table1(*ctx, o, scenarios_from(*file), *seeds, part, &wall);
      write_timing(o, "table1", wall);
      if (c->json != "-") {
        if (part.whole()) std::cout << j["markdown"].get<std::string>();
        std::cout << "wall time " << wall << " s on " << util::worker_count(o.threads) << " threads\n";
      }
      emit(*c, j);
    });
  }
  {
    auto c = std::make_shared<CliCommon>();
    auto target = std::make_shared<std::string>("cortex-m0");
    auto scenario = std::make_shared<std::string>("j20-a0.2-p1");
    auto approach = std::make_shared<std::string>("B");
    auto duration = std::make_shared<double>(4.0);
    auto table1 = std::make_shared<bool>(false);
    auto seeds = std::make_shared<std::size_t>(2);
    auto fw_dir = std::make_shared<std::string>();
    auto fault_every = std::make_shared<int>(0);
    auto timeout_ms = std::make_shared<int>(2000);
    CLI::App* cmd = app.add_subcommand(
        "pil", "Processor in the loop: the control job runs in the firmware under QEMU, the harness plays the board; "
               "compared with the host run on the same seeds");
    add_common(cmd, *c, "out/pil");
    cmd->add_option("--target", *target, "MCU: cortex-m0 (QEMU microbit) or cortex-m4f (QEMU mps2-an386)")
        ->check(CLI::IsMember({"cortex-m0", "cortex-m4f"}))
        ->capture_default_str();
    cmd->add_option("--approach", *approach, "approach A-E")->check(CLI::IsMember({"A", "B", "C", "D", "E", "a", "b", "c", "d", "e"}))->capture_default_str();
    cmd->add_option("--scenario", *scenario, "built-in scenario")->capture_default_str();
    cmd->add_option("--duration", *duration, "simulated seconds")->check(finite_in(0.05, 3600.0))->capture_default_str();
    cmd->add_flag("--table1", *table1, "run Table I (every approach and scenario) through the MCU");
    cmd->add_option("--seeds", *seeds, "seeds per scenario with --table1")->check(CLI::Range(2, 1000))->capture_default_str();
    cmd->add_option("--firmware-dir", *fw_dir, "build tree holding firmware-<target>/ (default: this build's)");
    cmd->add_option("--inject-faults", *fault_every,
                    "link test: damage every N-th request (corrupt byte, dropped byte, lost reply in turn); 0: never")
        ->check(CLI::Range(0, 1'000'000))
        ->capture_default_str();
    cmd->add_option("--reply-timeout-ms", *timeout_ms, "wait this long for a reply before resending")
        ->check(CLI::Range(10, 600'000))
        ->capture_default_str();
    cmd->callback([=]() {
      const auto ctx = SimContext::load(c->plant);
      PilOptions p;
      p.target = *target;
      p.firmware_dir = *fw_dir;
      p.fault_every = *fault_every;
      p.timeout_ms = *timeout_ms;
      const CommonOptions o = c->resolve();
      nlohmann::json j;
      if (*table1) {
        std::vector<Scenario> scenarios = default_scenarios();
        for (Scenario& s : scenarios) s.duration_s = *duration;
        j = run_pil_table1(*ctx, o, p, scenarios, *seeds);
        if (c->json != "-") std::cout << j["markdown"].get<std::string>();
      } else {
        Scenario sc = find_scenario(default_scenarios(), *scenario);
        sc.duration_s = *duration;
        j = run_pil_compare(*ctx, o, p, sc, parse_approach(*approach));
        if (c->json != "-") util::write_json("-", j);
      }
      if (!c->json.empty()) util::write_json(c->json, j);
    });
  }
  {
    auto c = std::make_shared<CliCommon>();
    auto target = std::make_shared<std::string>("host");
    auto fw_dir = std::make_shared<std::string>();
    CLI::App* cmd = app.add_subcommand("exectime",
                                       "Experiment 5: execution time of the control job over 4 s (host clock and callgrind); "
                                       "both noise models are measured, the original constant Q first");
    c->noise = "constant";  // the brief's protocol measures the original design
    add_common(cmd, *c, "out/exectime");
    cmd->add_option("--target", *target,
                    "host (steady clock and callgrind), or an MCU under QEMU: cortex-m0, cortex-m4f (instructions per job)")
        ->check(CLI::IsMember({"host", "cortex-m0", "cortex-m4f"}))
        ->capture_default_str();
    cmd->add_option("--firmware-dir", *fw_dir, "build tree holding firmware-<target>/ (default: this build's)");
    auto profile_dir = std::make_shared<std::string>();
    cmd->add_option("--profile-dir", *profile_dir,
                    "with an MCU target: also write, per image, how often each instruction address ran inside the "
                    "jobs (<image>.profile; symbolize with arm-none-eabi-addr2line)");
    cmd->callback([c, target, fw_dir, profile_dir]() {
      const auto ctx = SimContext::load(c->plant);
      if (*target == "host") {
        emit(*c, run_exectime(*ctx, c->resolve(), self_path()));
        return;
      }
      PilOptions p;
      p.target = *target;
      p.firmware_dir = *fw_dir;
      p.profile_dir = *profile_dir;
      const nlohmann::json j = run_exectime_target(*ctx, c->resolve(), p);
      if (c->json != "-") {
        for (const auto& [name, v] : j["variants"].items()) {
          std::printf("%-24s %8.0f instructions/job  %8.0f per 4 s  flash %6zu B  RAM %5zu B + stack %5d B\n",
                      name.c_str(), v["instructions_per_job"].get<double>(), v["instructions_per_4s"].get<double>(),
                      v["flash_bytes"].get<std::size_t>(), v["ram_bytes"].get<std::size_t>(),
                      v["stack_peak_bytes"].get<int>());
        }
      }
      if (!c->json.empty()) util::write_json(c->json, j);
    });
  }
  {
    auto variant = std::make_shared<std::string>();
    CLI::App* cmd = add_experiment(
        app, "exectime-probe", "(internal) replay one variant for callgrind", "out/exectime",
        [variant](const CliCommon& c, const SimContext& ctx) { run_exectime_probe(ctx, c.resolve(), *variant); }, "constant");
    cmd->group("");  // hidden
    cmd->add_option("--variant", *variant, "half_table, half_generic, complete_table or complete_generic")->required();
  }
  {
    auto c = std::make_shared<CliCommon>();
    auto approach = std::make_shared<std::string>("B");
    auto scenario = std::make_shared<std::string>("j20-a0.2-p1");
    auto file = std::make_shared<std::string>();
    auto duration = std::make_shared<double>(0.0);
    auto trace = std::make_shared<std::int32_t>(1000);
    auto jitter_model = std::make_shared<std::string>();
    auto jitter_us = std::make_shared<std::int32_t>(-1);
    auto trace_file = std::make_shared<std::string>();
    CLI::App* cmd = app.add_subcommand("run", "One configurable run with full traces");
    add_common(cmd, *c, "out/run");
    cmd->add_option("--approach", *approach, "approach A-E")->check(CLI::IsMember({"A", "B", "C", "D", "E", "a", "b", "c", "d", "e"}))->capture_default_str();
    cmd->add_option("--scenario", *scenario, "scenario name (built-in or from --scenarios)")->capture_default_str();
    cmd->add_option("--scenarios", *file, "scenario file")->check(CLI::ExistingFile);
    CLI::Option* duration_opt = cmd->add_option("--duration", *duration, "override the scenario duration (s)")
                                    ->check(finite_in(0.0, 3600.0, true));
    cmd->add_option("--jitter", *jitter_model, "override the jitter model: none, uniform or trace")->check(CLI::IsMember({"none", "uniform", "trace"}));
    cmd->add_option("--jitter-us", *jitter_us, "uniform jitter: largest release delay (us)")->check(CLI::Range(0, 10'000'000));
    cmd->add_option("--jitter-trace", *trace_file, "trace jitter: CSV 'release_us,exec_us'")->check(CLI::ExistingFile);
    cmd->add_option("--trace-step-us", *trace, "dense state trace step (0: none)")->check(CLI::Range(0, 1'000'000))->capture_default_str();
    cmd->callback([=]() {
      const auto ctx = SimContext::load(c->plant);
      Scenario sc = find_scenario(scenarios_from(*file), *scenario);
      if (duration_opt->count() > 0) sc.duration_s = *duration;
      // --jitter-us implies the uniform model and --jitter-trace the trace model; an option
      // that the chosen model would ignore is refused.
      const bool has_us = *jitter_us >= 0;
      const bool has_trace = !trace_file->empty();
      const std::string model = !jitter_model->empty() ? *jitter_model : has_trace ? "trace" : has_us ? "uniform" : "";
      if (has_trace && model != "trace") throw ScenarioError("--jitter-trace needs --jitter trace (got --jitter " + model + ")");
      if (has_us && model != "uniform") throw ScenarioError("--jitter-us needs --jitter uniform (got --jitter " + model + ")");
      if (model == "none") sc.jitter = JitterModel{};
      if (model == "uniform") {
        sc.jitter.kind = JitterModel::Kind::kUniform;
        if (has_us) sc.jitter.release_max_us = *jitter_us;
      }
      if (model == "trace") {
        if (!has_trace) throw ScenarioError("--jitter trace needs --jitter-trace FILE");
        sc.jitter.kind = JitterModel::Kind::kTrace;
        sc.jitter.trace_path = *trace_file;
        sc.jitter.trace = load_jitter_trace(*trace_file);
      }
      emit(*c, run_single(*ctx, c->resolve(), sc, parse_approach(*approach), *trace));
    });
  }
  {
    auto seconds = std::make_shared<double>(200.0);
    CLI::App* cmd = add_experiment(app, "benchmark", "Simulated seconds per wall second of the board emulation (one core)",
                                   "out/benchmark", [seconds](const CliCommon& c, const SimContext& ctx) {
                                     const nlohmann::json j = run_benchmark(ctx, c.resolve(), *seconds);
                                     if (c.json != "-") util::write_json("-", j);
                                     if (!c.json.empty()) util::write_json(c.json, j);
                                   });
    cmd->add_option("--simulated-seconds", *seconds, "simulated time per measurement")->check(finite_in(1.0, 1e5))->capture_default_str();
  }
  {
    auto c = std::make_shared<CliCommon>();
    auto seeds = std::make_shared<std::size_t>(20);
    auto outdir = std::make_shared<std::string>("out");
    auto file = std::make_shared<std::string>();
    CLI::App* cmd = app.add_subcommand("report", "Run every experiment and write OUTDIR/report.md with tables and plots");
    add_common(cmd, *c, "out");
    CLI::Option* outdir_opt = cmd->add_option("outdir", *outdir, "output folder (the same as --out)")->capture_default_str();
    cmd->add_option("--seeds", *seeds, "seeds per Table I scenario")->check(CLI::Range(2, 100000))->capture_default_str();
    cmd->add_option("--scenarios", *file, "scenario file for Table I")->check(CLI::ExistingFile);
    auto no_mcu = std::make_shared<bool>(false);
    auto fw_dir = std::make_shared<std::string>();
    cmd->add_flag("--no-mcu", *no_mcu, "leave out the firmware section (instruction counts and PIL under QEMU)");
    cmd->add_option("--firmware-dir", *fw_dir, "build tree holding firmware-<target>/ (default: this build's)");
    CLI::Option* out_opt = cmd->get_option("--out");
    cmd->callback([c, seeds, outdir, file, no_mcu, fw_dir, outdir_opt, out_opt]() {
      if (outdir_opt->count() > 0 && out_opt->count() > 0 && *outdir != c->opt.out_dir) {
        throw std::invalid_argument("two output folders given ('" + *outdir + "' and --out '" + c->opt.out_dir +
                                    "'): give one");
      }
      const auto ctx = SimContext::load(c->plant);
      CommonOptions o = c->resolve();
      o.out_dir = outdir_opt->count() > 0 ? *outdir : c->opt.out_dir;
      ReportOptions r;
      r.scenarios = scenarios_from(*file);
      r.seeds = *seeds;
      r.self_path = self_path();
      r.firmware_dir = *fw_dir;
      r.mcu = !*no_mcu;
      const nlohmann::json all = run_report(*ctx, o, r);
      if (!c->json.empty()) util::write_json(c->json, all);
      std::cout << "report: " << (std::filesystem::path(o.out_dir) / "report.md").string() << "\n";
    });
  }
}

}  // namespace oneshot::sim
