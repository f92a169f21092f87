/// @file ncs_study.cpp
/// @brief Study `ncs` (seed 001, networked actuation sync) under `oneshot-sim ncs …`:
///        table (E4, with --noise-free), e1, e2, e3; the merge summarizer; the report section.
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <sstream>

#include "ncs_analytic.hpp"
#include "ncs_experiments.hpp"
#include "ncs_faults.hpp"
#include "ncs_live.hpp"
#include "oneshot/sim/study_descriptor.hpp"
#include "oneshot/util/output_files.hpp"
#include "oneshot/sim/study_report.hpp"

namespace oneshot::sim {
namespace {

struct NcsCli {
  std::string plant;
  std::string out;
  std::string json;
  bool no_plots = false;
  std::uint64_t seed = 1;
};

void add_common(CLI::App* cmd, NcsCli& c, const std::string& default_out) {
  c.out = default_out;
  cmd->add_option("--plant", c.plant, "plant file (default: lut_gen/plants/networked_board.json)")->check(CLI::ExistingFile);
  cmd->add_option("--out", c.out, "output directory")->capture_default_str();
  cmd->add_option("--json", c.json, "write the result as JSON to PATH, or '-' for standard output");
  cmd->add_option("--seed", c.seed, "first seed")->capture_default_str();
  cmd->add_flag("--no-plots", c.no_plots, "write CSV files only (no gnuplot)");
}

void emit(const NcsCli& c, const nlohmann::json& j) {
  if (!c.json.empty()) util::write_json(c.json, j);
  if (c.json != "-") std::cout << "ncs " << j.value("experiment", std::string("result")) << ": written to " << c.out << "\n";
}

std::string fmt(const char* f, double v) {
  char b[64];
  std::snprintf(b, sizeof b, f, v);
  return b;
}

StudyReportResult report_section(const StudyReportContext& rc) {
  const auto ctx = ncs::Context::load("");
  ncs::TableOptions t;
  t.first_seed = rc.seed;
  t.threads = static_cast<unsigned>(rc.threads);
  t.seeds = 50;
  const nlohmann::json table = ncs::table_outputs(ncs::table_sweep(*ctx, t, engine::Shard{}),
                                                  (std::filesystem::path(rc.out_dir) / "table").string(), rc.plots);
  ncs::TableOptions nf = t;
  nf.noise_free = true;
  nf.seeds = 10;
  nf.approaches = {ncs::Approach::kI, ncs::Approach::kS, ncs::Approach::kA, ncs::Approach::kSPlus};
  const nlohmann::json free = ncs::table_outputs(ncs::table_sweep(*ctx, nf, engine::Shard{}),
                                                 (std::filesystem::path(rc.out_dir) / "noise_free").string(), rc.plots);
  const nlohmann::json e1 = ncs::run_e1(*ctx, rc.seed, 5, rc.out_dir, rc.plots);
  const nlohmann::json e2 = ncs::run_e2(*ctx, rc.seed, 4, rc.out_dir, rc.plots);
  const nlohmann::json e3 = ncs::run_e3(*ctx, rc.seed, 4, rc.out_dir, rc.plots);
  std::ostringstream md;
  md << "## Networked control synchronized at the actuation instants (study ncs)\n\n"
     << "Plant `" << ctx->plant().name << "` (C = I, h = 50 ms), ten scenarios of the brief, "
     << t.seeds << " seeds each, the same delay and noise draws for every approach (details: docs/ncs.md).\n\n"
     << ncs::table_section_markdown(table, {"S-A", "S-AK", "A-AK", "AK-AKx", "AK-AKl", "S-SK", "S-S+", "AK-SK", "AK-IK"},
                                    rc.plots ? rc.rel_dir + "/table/table.png" : "")
     << "Noise-free invariant (" << nf.seeds << " seeds): max |J_A/J_I - 1| = "
     << fmt("%.2e", free.at("A_vs_I_max_abs_ratio_minus_1").get<double>()) << "; S/I by delay level d:";
  for (const auto& [d, r] : free.at("S_ratio_to_I_by_delay_ms").items()) md << " d = " << d << " ms: " << fmt("%.4f", r.get<double>()) << ";";
  md << "\n\n" << free.at("markdown").get<std::string>() << "\n";
  md << "E1 (AK, " << e1.at("description").get<std::string>() << "): RMS measurement error "
     << fmt("%.4f", e1.at("rms_measurement_error_volts")[0].get<double>()) << " / "
     << fmt("%.4f", e1.at("rms_measurement_error_volts")[1].get<double>()) << " V, RMS estimate error at t_k "
     << fmt("%.4f", e1.at("rms_estimate_error_at_actuation_volts")[0].get<double>()) << " / "
     << fmt("%.4f", e1.at("rms_estimate_error_at_actuation_volts")[1].get<double>()) << " V (v1 / v2).\n\n";
  if (rc.plots) {
    md << "| | |\n|---|---|\n| ![e1](" << rc.rel_dir << "/e1.png) | ![e2](" << rc.rel_dir << "/e2.png) |\n| ![e3]("
       << rc.rel_dir << "/e3.png) | |\n\n";
  }
  StudyReportResult r;
  r.markdown = md.str();
  r.json = {{"table", table}, {"noise_free", free}, {"e1", e1}, {"e2", e2}, {"e3", e3}};
  for (auto* j : {&r.json["table"], &r.json["noise_free"]}) {
    j->erase("markdown");
    j->erase("markdown_per_scenario");
  }
  return r;
}

/// table, the e1–e3 experiments, analytic-benchmark, the live run and the faults sweep.
void add_ncs_commands(CLI::App* study) {
  {
    auto c = std::make_shared<NcsCli>();
    auto t = std::make_shared<ncs::TableOptions>();
    auto shard = std::make_shared<std::string>("0/1");
    auto approaches = std::make_shared<std::vector<std::string>>();
    auto scenario_file = std::make_shared<std::string>();
    auto inject = std::make_shared<std::string>();
    CLI::App* cmd = study->add_subcommand("table", "E4: every approach on the ten scenarios (95 % CI, paired differences)");
    add_common(cmd, *c, "out/ncs");
    cmd->add_option("--seeds", t->seeds, "seeds per scenario")->check(CLI::Range(2, 100000))->capture_default_str();
    cmd->add_flag("--noise-free", t->noise_free, "no process or measurement noise (delays stay): A must equal I");
    cmd->add_flag("--analytic", t->analytic,
                  "also the exact expected cost over the noise for each run's timing (analytic_mean, analytic_ci95, "
                  "variance_reduction; refused approaches named with the reason)");
    cmd->add_option("--duration", t->duration_s, "seconds per run")->check(CLI::Range(0.1, 3600.0))->capture_default_str();
    cmd->add_option("--scenarios", *scenario_file, "scenario file (default: the ten of the brief, sim_host/ncs/scenarios.json)")
        ->check(CLI::ExistingFile);
    cmd->add_option("--threads", t->threads, "worker threads (0: every core)")->capture_default_str();
    cmd->add_option("--approaches", *approaches, "approaches, I first (default: I S A AK AKx AKl SK S+ IK)");
    cmd->add_option("--inject", *inject, "faults in every run, e.g. 'dup:link=sc,rate=0.02;restart:node=sensor,at_s=5' (docs/faults.md)");
    cmd->add_option("--shard", *shard, "run part i/N of the sweep and write OUT/table.shard-i-of-N.json (`oneshot-sim merge`)")
        ->capture_default_str();
    cmd->callback([c, t, shard, approaches, scenario_file, inject]() {
      t->faults = engine::parse_fault_spec(*inject);
      const auto ctx = ncs::Context::load_board(c->plant);
      if (!scenario_file->empty()) t->scenarios = ncs::load_scenarios(*scenario_file);
      if (!approaches->empty()) {
        t->approaches.clear();
        for (const auto& a : *approaches) t->approaches.push_back(ncs::parse_approach(a));
      }
      t->first_seed = c->seed;
      const engine::Shard part = engine::parse_shard(*shard);
      util::make_directory(c->out);
      const auto start = std::chrono::steady_clock::now();
      const engine::SweepResults r = ncs::table_sweep(*ctx, *t, part);
      const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      util::write_json((std::filesystem::path(c->out) / "timing.json").string(), {{"experiment", "ncs table"}, {"wall_time_s", wall}});
      nlohmann::json j;
      if (!part.whole()) {
        j = engine::shard_to_json(r);
        util::write_json((std::filesystem::path(c->out) / engine::shard_file_name("table", part)).string(), j);
      } else {
        j = ncs::table_outputs(r, c->out, !c->no_plots);
        if (c->json != "-") std::cout << j.at("markdown").get<std::string>() << "order: " << j.at("order_text").get<std::string>() << "\n";
      }
      if (c->json != "-") std::cout << "wall time " << wall << " s\n";
      emit(*c, j);
    });
  }
  const auto trace_cmd = [study](const char* nm, const char* help, double duration,
                                 nlohmann::json (*f)(const ncs::Context&, std::uint64_t, double, const std::string&, bool)) {
    auto c = std::make_shared<NcsCli>();
    auto d = std::make_shared<double>(duration);
    CLI::App* cmd = study->add_subcommand(nm, help);
    add_common(cmd, *c, std::string("out/ncs-") + nm);
    cmd->add_option("--duration", *d, "simulated seconds")->check(CLI::Range(0.1, 3600.0))->capture_default_str();
    cmd->callback([c, d, f]() {
      const auto ctx = ncs::Context::load_board(c->plant);
      emit(*c, f(*ctx, c->seed, *d, c->out, !c->no_plots));
    });
  };
  trace_cmd("e1", "E1 (Fig. 6): noisy y1, y2 beside AK's estimates", 5, &ncs::run_e1);
  trace_cmd("e2", "E2 (Fig. 7): delays only, I, S and A on the square wave", 4, &ncs::run_e2);
  trace_cmd("e3", "E3 (Fig. 8): delays, noise and disturbance, S, A and AK", 4, &ncs::run_e3);
  {
    auto c = std::make_shared<NcsCli>();
    CLI::App* cmd = study->add_subcommand("report", "This study's section of `oneshot-sim report` alone: OUT/ncs.md, OUT/ncs.json");
    add_common(cmd, *c, "out/ncs-report");
    cmd->callback([c]() {
      StudyReportContext rc;
      rc.out_dir = c->out;
      rc.rel_dir = ".";
      rc.seed = c->seed;
      rc.plots = !c->no_plots;
      util::make_directory(rc.out_dir);
      const StudyReportResult r = report_section(rc);
      std::ofstream((std::filesystem::path(c->out) / "ncs.md").string()) << r.markdown;
      util::write_json((std::filesystem::path(c->out) / "ncs.json").string(), r.json);
      nlohmann::json j = r.json;
      j["experiment"] = "report";
      emit(*c, j);
    });
  }
  {
    auto c = std::make_shared<NcsCli>();
    CLI::App* cmd = study->add_subcommand("analytic-benchmark",
                                          "Cost of `table --analytic`: covariance propagation per event, analytic run "
                                          "against the noise-free run (benchmark, not a test)");
    add_common(cmd, *c, "out/ncs-analytic-benchmark");
    cmd->callback([c]() { emit(*c, ncs::analytic_benchmark(*ncs::Context::load_board(c->plant), c->seed)); });
  }
  add_ncs_live_commands(study);
  add_ncs_faults_command(study);
  add_ncs_stationary_command(study);
}

}  // namespace

StudyDescriptor ncs_study() {
  return {"ncs",
          "Study 001: networked control synchronized at the actuation instants with a half Kalman filter "
          "(approaches I, S, A, AK, AKx, AKl, SK, S+, IK)",
          add_ncs_commands, {{"table", ncs::table_outputs}}, StudyReportSection{"ncs", report_section}};
}

}  // namespace oneshot::sim
