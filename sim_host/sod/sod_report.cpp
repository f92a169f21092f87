/// @file sod_report.cpp
/// @brief The send-on-delta report section (see sod_report.hpp).
#include "sod_report.hpp"

#include <sstream>

#include "oneshot/util/number_text.hpp"
#include "sod_experiments.hpp"

namespace oneshot::sod {
namespace {

std::string g4(double v) { return util::format_g(v, 4); }
std::string maybe(const nlohmann::json& v) { return v.is_null() ? "unbounded" : g4(v.get<double>()); }
std::string ci(const nlohmann::json& v) { return g4(v.at("mean").get<double>()) + " ± " + g4(v.at("ci95").get<double>()); }

}  // namespace

sim::StudyReportResult report_section(const sim::StudyReportContext& ctx) {
  StudyOptions opt;
  opt.plant_path = default_sod_plant_path();
  opt.out_dir = ctx.out_dir;
  opt.threads = static_cast<unsigned>(ctx.threads);
  opt.seed = ctx.seed;
  opt.plots = ctx.plots;
  const SodModel model = load_sod_model(opt.plant_path);
  nlohmann::json j;
  std::ostringstream md;
  md << "## Send-on-delta estimation over a lossy link (study sod)\n\n"
     << "Plant `" << model.plant_name << "` (brief §1, Q_c = 0.01·I₂, R = 0.01·I₂, T = 10 ms), unit step input, "
     << "N = " << opt.steps << " steps, δy = " << opt.delta_y << ", μ = " << opt.mu << ", " << opt.seeds
     << " Monte Carlo runs per cell, 95 % Student-t intervals over seeds; every configuration of a seed sees the same "
        "plant, measurement and loss draws (paired differences). Page: docs/sod.md.\n\n";

  const nlohmann::json design = run_design(model, opt);
  j["design"] = design;
  md << "### δt design (§5)\n\nΔT (E1, lossless plain SOD): node 1 " << g4(design.at("mean_gap_s")[0].get<double>()) << " ± "
     << g4(design.at("mean_gap_ci95_s")[0].get<double>()) << " s, node 2 " << g4(design.at("mean_gap_s")[1].get<double>())
     << " ± " << g4(design.at("mean_gap_ci95_s")[1].get<double>()) << " s; diag P0 = (" << g4(design.at("p0_diag")[0].get<double>())
     << ", " << g4(design.at("p0_diag")[1].get<double>()) << ").\n\n"
     << "| ξ | δt*₁ (s) | δt*₂ (s) | δt*₁·ξ | δt*₂·ξ | active constraint | grid check |\n|---|---|---|---|---|---|---|\n";
  for (const auto& e : design.at("per_loss")) {
    std::string active;
    for (const auto& a : e.at("active_constraints")) active += (active.empty() ? "" : ", ") + a.get<std::string>();
    md << "| " << e.at("loss").get<double>() << " | " << maybe(e.at("delta_t_s")[0]) << " | " << maybe(e.at("delta_t_s")[1])
       << " | " << maybe(e.at("delta_t_times_loss_s")[0]) << " | " << maybe(e.at("delta_t_times_loss_s")[1]) << " | "
       << (active.empty() ? "none" : active) << " | " << (e.at("grid_check").at("passed").get<bool>() ? "passed" : "FAILED") << " |\n";
  }
  md << "\n";

  const nlohmann::json table = run_table(model, opt);
  j["table"] = table;
  md << "### E3: configurations × loss rate\n\n" << table.at("markdown").get<std::string>() << "\nPaired differences (same seeds):\n\n"
     << table.at("markdown_paired").get<std::string>() << "\nPlain SOD sends the same packets at every ξ for each seed: "
     << (table.at("sod_packets_identical_across_loss").get<bool>() ? "yes" : "NO") << ".\n\n![E3](" << ctx.rel_dir << "/table.png)\n\n";

  const nlohmann::json curve = run_curve(model, opt, {0.1, 0.3, 1, 3, 10, 30}, {0.05, 0.2});
  j["curve"] = curve;
  md << "### E3 (d): error against packets\n\n| ξ | sender | δt (s) | packets (event) | e₁ event | e₁ periodic, same budget | paired e₁ event − periodic |\n"
        "|---|---|---|---|---|---|---|\n";
  for (const auto& r : curve.at("rows")) {
    md << "| " << r.at("loss").get<double>() << " | " << r.at("sender").get<std::string>() << " | "
       << (r.at("delta_t_s").is_null() ? "∞" : g4(r.at("delta_t_s").get<double>())) << " | "
       << g4(r.at("event").at("packets").at("mean").get<double>()) << " | " << ci(r.at("event").at("e1")) << " | "
       << ci(r.at("periodic").at("e1")) << " | " << ci(r.at("paired_event_minus_periodic").at("e1")) << " |\n";
  }
  md << "\n![E3d](" << ctx.rel_dir << "/curve.png)\n\n";

  StudyOptions e2 = opt;
  e2.seeds = 20;  // ΔT per δy: 20 lossless runs each (the design, not the error, uses them)
  const nlohmann::json grid = run_grid(model, e2, {0.1, 0.25, 0.5, 0.75, 1.0}, {0.05, 0.1, 0.15, 0.2});
  j["grid"] = grid;
  md << "### E2: δt* over δy × ξ\n\nΔT from 20 lossless runs per δy.\n\n| δy | ΔT₁ (s) | ξ | δt*₁ (s) | δt*₂ (s) |\n|---|---|---|---|---|\n";
  for (const auto& r : grid.at("rows"))
    for (const auto& e : r.at("per_loss"))
      md << "| " << r.at("delta_y").get<double>() << " | " << g4(r.at("mean_gap_s")[0].get<double>()) << " | "
         << e.at("loss").get<double>() << " | " << maybe(e.at("delta_t_s")[0]) << " | " << maybe(e.at("delta_t_s")[1]) << " |\n";
  md << "\n![E2](" << ctx.rel_dir << "/e2_delta_t.png)\n\n";

  const nlohmann::json traces = run_traces(model, opt, 0.05);
  j["traces"] = traces;
  md << "### E4: error over time, ξ = 0.05\n\n| configuration | e₁ 0–20 s | e₁ 20–50 s | e₂ 0–20 s | e₂ 20–50 s |\n|---|---|---|---|---|\n";
  for (const char* a : {"sod-held", "msod"}) {
    const auto& m = traces.at("mean_error").at(a);
    md << "| " << a << " | " << g4(m.at("e1_0_20s").get<double>()) << " | " << g4(m.at("e1_20s_end").get<double>()) << " | "
       << g4(m.at("e2_0_20s").get<double>()) << " | " << g4(m.at("e2_20s_end").get<double>()) << " |\n";
  }
  md << "\n![E4](" << ctx.rel_dir << "/e4_traces.png)\n\n";
  return {md.str(), j};
}

}  // namespace oneshot::sod
