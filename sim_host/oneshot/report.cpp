/// @file report.cpp
/// @brief `oneshot-sim report`: every experiment, the number formats, the table, the
///        firmware on both MCUs, and the product targets, in one Markdown page.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <sstream>

#include "oneshot/util/file_io.hpp"
#include "oneshot_experiments.hpp"
#include "table1_analytic.hpp"
#include "oneshot/sim/study_report.hpp"
#include "oneshot/util/output_files.hpp"
#include "oneshot/util/parallel.hpp"
#include "oneshot/sim/pil_link.hpp"

namespace oneshot::sim {
namespace {

std::string fmt(const char* f, double v) {
  char b[64];
  std::snprintf(b, sizeof b, f, v);
  return b;
}

CommonOptions in_subdir(const CommonOptions& o, const std::string& sub) {
  CommonOptions r = o;
  r.out_dir = (std::filesystem::path(o.out_dir) / sub).string();
  return r;
}

/// Table I in double, float and fixed point on the same seeds.
nlohmann::json number_formats(const SimContext& ctx, const CommonOptions& o, const nlohmann::json& float_table,
                              const ReportOptions& r, std::ostringstream& md) {
  nlohmann::json j;
  j["float"] = float_table;
  for (NumberFormat f : {NumberFormat::kDouble, NumberFormat::kFixed}) {
    CommonOptions of = in_subdir(o, std::string("formats/") + to_string(f));
    of.format = f;
    of.plots = false;
    j[to_string(f)] = run_table1(ctx, of, r.scenarios, r.seeds);
  }
  md << "## 5. Number formats\n\nTable I again with the control job in double and in fixed point (same scenarios "
        "and seeds; the float column is section 4).\n\n| approach | double | float | fixed | float vs double | fixed vs double |\n"
        "|---|---|---|---|---|---|\n";
  double worst_fixed = 0;
  for (const char* a : {"A", "B", "C", "D", "E"}) {
    const double d = j["double"]["approaches"][a]["cost_mean"].get<double>();
    const double fl = j["float"]["approaches"][a]["cost_mean"].get<double>();
    const double fx = j["fixed"]["approaches"][a]["cost_mean"].get<double>();
    worst_fixed = std::max(worst_fixed, std::fabs(fx / d - 1));
    md << "| " << a << " | " << fmt("%.6f", d) << " | " << fmt("%.6f", fl) << " | " << fmt("%.6f", fx) << " | "
       << fmt("%+.4f %%", 100 * (fl / d - 1)) << " | " << fmt("%+.4f %%", 100 * (fx / d - 1)) << " |\n";
  }
  j["fixed_worst_relative_difference"] = worst_fixed;
  md << "\nFixed-point runs that raised the saturation flag: " << j["fixed"]["saturated_runs"].get<std::size_t>()
     << " of " << j["fixed"]["runs"].get<std::size_t>() << ".\n\n";
  return j;
}

/// The generated table of the build (built-in plant only).
nlohmann::json table_section(const SimContext& ctx, std::ostringstream& md) {
  md << "## 6. The Phi/Gamma/Q_d table\n\n";
  std::string text;
  if (ctx.generated()) {
    try {
      text = util::read_text_file(ONESHOT_LUT_REPORT_PATH, "table report");
    } catch (const util::FileError&) {
      text.clear();  // a build without the generated table: reported below
    }
  }
  if (text.empty()) {
    md << "The build-time table belongs to the built-in plant; see `lut_report.json` of a build with "
          "`-DONESHOT_PLANT=FILE`.\n\n";
    return nullptr;
  }
  const nlohmann::json lut = nlohmann::json::parse(text);
  const auto& f = lut["formats"];
  md << "| format | bytes | levels | entries | max abs error vs double generic |\n|---|---|---|---|---|\n"
     << "| float | " << f["float"]["bytes"] << " | " << f["float"]["levels"] << " | " << f["float"]["entries"] << " | "
     << fmt("%.3g", f["float"]["max_abs_error"].get<double>()) << " |\n"
     << "| double | " << f["double"]["bytes"] << " | " << f["double"]["levels"] << " | " << f["double"]["entries"] << " | "
     << fmt("%.3g", f["double"]["max_abs_error"].get<double>()) << " |\n";
  if (f["fixed"].value("available", false)) {
    md << "| fixed (block, 16-bit mantissas) | " << f["fixed"]["bytes"] << " | " << f["fixed"]["levels"] << " | "
       << f["fixed"]["entries"] << " | " << fmt("%.3g", f["fixed"]["max_quantization_error"].get<double>())
       << " (quantization) |\n";
  }
  md << "\nGranularity " << lut["granularity_us"] << " us over 0-" << lut["range_us"] << " us; budget `table.max_bytes` "
     << lut["max_bytes"] << ".\n\n";
  return lut;
}

/// Instruction counts and processor-in-the-loop runs on both MCUs.
nlohmann::json mcu_section(const SimContext& ctx, const CommonOptions& o, const ReportOptions& r, std::ostringstream& md) {
  md << "## 7. The firmware on the MCUs (QEMU)\n\n";
  nlohmann::json j;
  if (!ctx.generated()) {
    md << "The firmware images carry the built-in plant: run without `--plant` for this section.\n\n";
    return j;
  }
  try {
    for (const char* target : {"cortex-m0", "cortex-m4f"}) {
      std::cerr << "report: exectime on " << target << "\n";
      PilOptions p;
      p.target = target;
      p.firmware_dir = r.firmware_dir;
      CommonOptions oe = o;
      oe.noise = NoiseModel::kConstant;
      j["exectime"][target] = run_exectime_target(ctx, oe, p);
      // The measured counts as a file of their own: `oneshot kernel` (and its report section) reads them.
      util::write_json((std::filesystem::path(o.out_dir) / (std::string("exectime-") + target + ".json")).string(),
                 j["exectime"][target]);
    }
    md << "Instructions per control job (QEMU TCG plugin, exact), over the " << j["exectime"]["cortex-m0"]["jobs_per_4s"]
       << " jobs of 4 s, constant Q as in the brief's experiment 5; image sizes from the ELF files, stack peak from "
          "the firmware's painted stack.\n\n"
          "| variant | M0 instr/job | M4F instr/job | M0 flash (B) | M0 RAM static + stack peak (B) |\n|---|---|---|---|---|\n";
    for (const auto& [name, v] : j["exectime"]["cortex-m0"]["variants"].items()) {
      const auto& v4 = j["exectime"]["cortex-m4f"]["variants"][name];
      md << "| " << name << " | " << std::lround(v["instructions_per_job"].get<double>()) << " | "
         << std::lround(v4["instructions_per_job"].get<double>()) << " | " << v["flash_bytes"] << " | " << v["ram_bytes"]
         << " + " << v["stack_peak_bytes"] << " |\n";
    }
    md << "\nProcessor in the loop: the job in the MCU, the board on the host, 20 s of scenario j20-a0.5-p1, seed "
       << o.seed << ", compared with the same run on the host.\n\n"
          "| target | format | approach | jobs | bit-identical | host cost | MCU cost | wall (s) |\n|---|---|---|---|---|---|---|---|\n";
    const Scenario sc = find_scenario(default_scenarios(), "j20-a0.5-p1");
    bool all_identical = true;
    for (const char* target : {"cortex-m0", "cortex-m4f"})
      for (NumberFormat f : {NumberFormat::kFloat, NumberFormat::kFixed})
        for (Approach a : {Approach::kB, Approach::kD}) {
          std::cerr << "report: pil " << target << " " << to_string(f) << " " << info(a).letter << "\n";
          PilOptions p;
          p.target = target;
          p.firmware_dir = r.firmware_dir;
          CommonOptions op = o;
          op.format = f;
          op.plots = false;
          const nlohmann::json c = run_pil_compare(ctx, op, p, sc, a);
          all_identical = all_identical && c["bit_identical"].get<bool>();
          j["pil"].push_back(c);
          md << "| " << target << " | " << to_string(f) << " | " << info(a).letter << " | " << c["jobs"] << " | "
             << (c["bit_identical"].get<bool>() ? "yes" : "**no**") << " | " << fmt("%.6f", c["host_cost"].get<double>())
             << " | " << fmt("%.6f", c["pil_cost"].get<double>()) << " | " << fmt("%.2f", c["pil_wall_time_s"].get<double>())
             << " |\n";
        }
    j["all_bit_identical"] = all_identical;
    md << "\n";
  } catch (const PilError& e) {
    md << "Skipped: " << e.what() << "\n\n";
    j["skipped"] = e.what();
  }
  return j;
}

/// The figures the product is judged against, measured above.
void targets_section(const nlohmann::json& table1, const nlohmann::json& analytic, const nlohmann::json& lut,
                     const nlohmann::json& mcu, const nlohmann::json& bench, nlohmann::json& out,
                     std::ostringstream& md) {
  md << "## 8. Targets\n\n| target | aim | measured |\n|---|---|---|\n";
  const auto& b = table1["approaches"]["B"];
  const double gap = b["ratio_mean"].get<double>() - 1;
  md << "| one-shot + Kalman (B) vs jitter-free (A), emulated board, Monte Carlo | within 0.2 % | "
     << fmt("%+.2f %%", 100 * gap) << " ± " << fmt("%.2f %%", 100 * b["ratio_ci95"].get<double>()) << " |\n";
  out["b_over_a_minus_1"] = gap;
  if (analytic.contains("B_over_A")) {
    const auto& r = analytic["B_over_A"];
    const auto& cw = r["cost_weighted"];
    const auto& sw = r["scenario_weighted"];
    const auto figure = [&](const nlohmann::json& a) {
      return fmt("%+.3f %%", 100 * (a["analytic_mean"].get<double>() - 1)) + " ± " +
             fmt("%.3f %%", 100 * a["analytic_ci95"].get<double>()) + ": " + a["within_0_2_percent"].get<std::string>();
    };
    md << "| the same, linear board, exact E[J] per timing draw | within 0.2 %, decided | scenario-weighted (mean of "
          "the per-scenario B/A) "
       << figure(sw) << "; cost-weighted (ratio of the scenario-summed costs) " << figure(cw) << "; within in "
       << r["scenarios_within"].get<std::size_t>() << " of " << r["scenarios"].get<std::size_t>()
       << " scenarios (section 4a) |\n";
    out["b_over_a_minus_1_analytic_cost_weighted"] = cw["analytic_mean"].get<double>() - 1;
    out["b_over_a_minus_1_analytic_scenario_weighted"] = sw["analytic_mean"].get<double>() - 1;
    out["b_within_0_2_percent_analytic_cost_weighted"] = cw["within_0_2_percent"];
    out["b_within_0_2_percent_analytic_scenario_weighted"] = sw["within_0_2_percent"];
    out["scenarios_within_0_2_percent_analytic"] = r["scenarios_within"];
  }
  if (!lut.is_null()) {
    md << "| reference table (float) | <= 256 B | " << lut["formats"]["float"]["bytes"] << " B |\n";
    out["table_bytes_float"] = lut["formats"]["float"]["bytes"];
  }
  if (mcu.contains("exectime")) {
    const auto& v = mcu["exectime"]["cortex-m0"]["variants"];
    const auto best = [&](const char* format) {
      double m = 1e300;
      std::string which;
      for (const auto& [name, x] : v.items()) {
        if (name.find(format) == std::string::npos) continue;
        if (x["instructions_per_job"].get<double>() < m) {
          m = x["instructions_per_job"].get<double>();
          which = name;
        }
      }
      out["m0_best_" + std::string(format)] = {{"variant", which}, {"instructions_per_job", m}};
      return std::to_string(std::lround(m)) + " (" + which + ")";
    };
    md << "| whole job on Cortex-M0, float | <= 6000 instructions | " << best("float") << " |\n"
       << "| whole job on Cortex-M0, fixed | <= 1500 instructions | " << best("fixed") << " |\n";
  }
  double slowest = 1e300;
  for (const auto& [k, x] : bench["real_time_factor_one_core"].items()) slowest = std::min(slowest, x.get<double>());
  md << "| board emulation per core | >= 2000x real time | " << std::lround(slowest) << "x (slowest approach) |\n";
  out["emulation_real_time_factor_min"] = slowest;
  if (mcu.contains("all_bit_identical")) {
    md << "| host float vs MCU | bit-identical | " << (mcu["all_bit_identical"].get<bool>() ? "yes" : "**no**")
       << " (every run of section 7) |\n";
  }
  md << "\n";
}

}  // namespace

nlohmann::json run_report(const SimContext& ctx, const CommonOptions& o, const ReportOptions& r) {
  // Refuse bad scenarios before anything is run or written.
  for (const Scenario& s : r.scenarios) validate_scenario(s, ctx.plant());
  const auto t0 = std::chrono::steady_clock::now();
  std::cerr << "report: noise\n";
  const nlohmann::json noise = run_noise_experiment(ctx, o, 5.0);
  std::cerr << "report: jitter\n";
  const nlohmann::json jitter = run_jitter_experiment(ctx, o, 6.0, 20'000);
  std::cerr << "report: gain\n";
  const nlohmann::json gain = run_gain_experiment(ctx, o, 3.0, 100.0);
  std::cerr << "report: table1\n";
  double table1_wall_s = 0;
  const nlohmann::json table1 = run_table1(ctx, o, r.scenarios, r.seeds, engine::Shard{}, &table1_wall_s);
  std::cerr << "report: exectime\n";
  CommonOptions oe = o;
  oe.noise = NoiseModel::kConstant;  // experiment 5 measures the original design; exact Q_d beside it
  const nlohmann::json exectime = run_exectime(ctx, oe, r.self_path);
  std::cerr << "report: benchmark\n";
  const nlohmann::json bench = run_benchmark(ctx, o, 100.0);

  std::ostringstream md;
  md << "# oneshot report: " << ctx.plant().name << "\n\n"
     << "Plant: " << ctx.plant().source << ". Control job in " << to_string(o.format) << ", " << to_string(o.discretizer)
     << " discretization, " << (o.noise == NoiseModel::kExact ? "exact Q_d(tau)" : "constant Q") << ", seed " << o.seed
     << ". Generated by `oneshot-sim report`.\n\n"
     << "## 1. Noise removal\n\n![noise](noise.png)\n\n"
     << "RMS error of the ADC reading: " << noise["rms_measurement_error_volts"].get<double>() * 1e3
     << " mV; of the estimate at the actuation instant: " << noise["rms_estimate_error_volts"].get<double>() * 1e3
     << " mV (factor " << noise["noise_reduction_factor"].get<double>() << ").\n\n"
     << "## 2. Jitter\n\n![jitter](jitter.png)\n\n| approach | cost J over the run |\n|---|---|\n";
  for (const auto& [k, v] : jitter["cost"].items()) md << "| " << k << " | " << v.get<double>() << " |\n";
  md << "\n## 3. Kalman gain evolution\n\n![gain](gain.png)\n\nSteady-state K(1) = " << gain["steady_state_K1"].get<double>()
     << "; spread of K(1) over the second half: half " << gain["K1_spread_second_half"]["half"].get<double>()
     << ", complete " << gain["K1_spread_second_half"]["complete"].get<double>() << ", standard "
     << gain["K1_spread_second_half"]["standard"].get<double>() << ".\n\n"
     << "## 4. Table I\n\n" << table1["seeds"].get<std::size_t>() << " seeds x " << table1["scenarios"].get<std::size_t>()
     << " scenarios, " << table1_wall_s << " s wall on " << util::worker_count(o.threads)
     << " threads.\n\n" << table1["markdown"].get<std::string>() << "\n![table1](table1.png)\n\nPer scenario:\n\n"
     << table1["markdown_per_scenario"].get<std::string>() << "\n";
  // The linear board's exact expected cost decides B vs A (the compiled-in plant only).
  nlohmann::json analytic;
  if (ctx.generated()) {
    std::cerr << "report: table1 --analytic\n";
    double analytic_wall_s = 0;
    analytic = run_table1_analytic(ctx, o, r.scenarios, r.seeds, &analytic_wall_s);
    md << "## 4a. Table I, analytic: the linear board\n\nThe same timing draws on the board with the PWM "
          "averaged and the ADC unquantized, where the loop is linear given the timing: the exact expected cost "
          "over the noise per draw, beside one Monte Carlo draw of the same model and the emulated board "
          "(docs/oneshot.md). B/A over the scenarios is given two ways: cost-weighted (the ratio of the "
          "scenario-summed costs: the scenarios with large costs dominate) and scenario-weighted (the mean of the "
          "per-scenario ratios: each scenario counts the same). "
       << analytic["seeds"].get<std::size_t>() << " timing draws x " << analytic["scenarios"].get<std::size_t>()
       << " scenarios, " << fmt("%.2f", analytic_wall_s) << " s wall.\n\n" << analytic["markdown"].get<std::string>()
       << "\n";
  }
  std::cerr << "report: number formats\n";
  const nlohmann::json formats = number_formats(ctx, o, table1, r, md);
  const nlohmann::json lut = table_section(ctx, md);
  const nlohmann::json mcu = r.mcu ? mcu_section(ctx, o, r, md) : nlohmann::json();

  md << "## Execution time on this host (" << to_string(o.format) << ", " << exectime["jobs_per_4s"].get<std::size_t>()
     << " jobs in 4 s)\n\n| noise model | variant | ns per job | us per 4 s | instructions per job |\n|---|---|---|---|---|\n";
  for (const auto& [model, variants] : exectime["variants_by_noise_model"].items()) {
    for (const auto& [k, v] : variants.items()) {
      md << "| " << model << " | " << k << " | " << v["host_ns_per_job"].get<double>() << " | "
         << v["host_us_per_4s"].get<double>() << " | "
         << (!v.contains("host_instructions_per_job") ? std::string("n/a")
                                                      : std::to_string(std::lround(v["host_instructions_per_job"].get<double>())))
         << " |\n";
    }
  }
  md << "\n![exectime](exectime.png)\n\n## Benchmark\n\nReal-time factor of the board emulation on one core: ";
  for (const auto& [k, v] : bench["real_time_factor_one_core"].items()) md << k << " " << static_cast<long>(v.get<double>()) << "x; ";
  md << "full Table I: " << fmt("%.2f", table1_wall_s) << " s wall.\n\n";

  nlohmann::json targets;
  targets_section(table1, analytic, lut, mcu, bench, targets, md);

  // The networked and event-based studies, each on its built-in defaults (study_report.hpp).
  StudyReportContext sections;
  sections.out_dir = o.out_dir;
  sections.threads = o.threads;
  sections.seed = o.seed;
  sections.plots = o.plots;
  const nlohmann::json studies = run_study_report_sections(sections, md);

  nlohmann::json all = {{"noise", noise},         {"jitter", jitter},     {"gain", gain},
                        {"table1", table1},       {"formats", formats},   {"exectime", exectime},
                        {"benchmark", bench},     {"targets", targets},   {"studies", studies}};
  if (!lut.is_null()) all["table"] = lut;
  if (!analytic.is_null()) all["table1_analytic"] = analytic;  // sections that did not run are left out, not null
  if (!mcu.is_null()) all["mcu"] = mcu;
  all["wall_time_s"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  util::write_json((std::filesystem::path(o.out_dir) / "report.json").string(), all);
  util::write_text((std::filesystem::path(o.out_dir) / "report.md").string(), md.str());
  return all;
}

}  // namespace oneshot::sim
