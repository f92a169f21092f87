/// @file ncs_faults.cpp
/// @brief The fault table (see ncs_faults.hpp) and the command `ncs faults`.
#include "ncs_faults.hpp"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <sstream>

#include "ncs_live.hpp"
#include "ncs_loop.hpp"
#include "oneshot/engine/sweep.hpp"
#include "oneshot/sim/cli_commands.hpp"
#include "oneshot/util/output_files.hpp"
#include "oneshot/util/statistics.hpp"

namespace oneshot::ncs {
namespace {

const char* receiver(const std::string& link) {
  return link == "as" ? "sensor" : link == "sc" ? "controller" : "actuator";
}

std::string fmt(const char* f, double v) {
  char b[64];
  std::snprintf(b, sizeof b, f, v);
  return b;
}

}  // namespace

std::vector<FaultCase> default_fault_cases(Approach a) {
  std::vector<FaultCase> out;
  for (const std::string& l : link_names(a)) {
    const std::string node = receiver(l);
    out.push_back({"nan " + l, node, "nan:link=" + l + ",rate=0.02"});
    out.push_back({"flip " + l, node, "flip:link=" + l + ",bits=1,rate=0.02"});
    out.push_back({"dup " + l, node, "dup:link=" + l + ",rate=0.05"});
    out.push_back({"replay " + l, node, "replay:link=" + l + ",age_ms=200,rate=0.02"});
    out.push_back({"forge_seq " + l, node, "forge_seq:link=" + l + ",at_s=2"});
  }
  for (const std::string& n : node_names()) out.push_back({"restart " + n, n, "restart:node=" + n + ",at_s=2"});
  return out;
}

nlohmann::json fault_table(const Context& ctx, const FaultTableOptions& o) {
  if (o.seeds < 2) throw std::invalid_argument("ncs faults needs at least 2 seeds for confidence intervals");
  const std::vector<FaultCase> cases = o.cases.empty() ? default_fault_cases(o.approach) : o.cases;
  std::vector<engine::FaultSpec> specs;
  for (const FaultCase& c : cases) {
    specs.push_back(engine::parse_fault_spec(c.spec));
    engine::check_fault_targets(specs.back(), link_names(o.approach), node_names());
  }
  const std::vector<std::string> counters = counter_names(o.approach);
  engine::SweepSpec spec;
  spec.study = "ncs";
  spec.experiment = "faults";
  spec.approaches.push_back("clean");
  for (const FaultCase& c : cases) spec.approaches.push_back(c.name);
  spec.scenarios = {o.scenario.name};
  spec.first_seed = o.first_seed;
  spec.seeds = o.seeds;
  spec.metrics = {"cost", "injected"};
  for (const auto& n : counters) spec.metrics.push_back(n);
  const engine::SweepResults r = engine::run_sweep(
      spec, engine::Shard{}, o.threads,
      [&](std::size_t a, std::size_t, std::uint64_t seed) {
        RunOptions ro;
        if (a > 0) ro.faults = specs[a - 1];
        const RunResult run = ncs::run(ctx, o.approach, o.scenario, seed, ro);
        std::vector<double> v = {run.cost, static_cast<double>(run.injected.injected())};
        v.insert(v.end(), run.counters.begin(), run.counters.end());
        return v;
      },
      "ncs faults");
  const auto mean_of = [&](std::size_t a, std::size_t m) {
    double s = 0;
    for (std::size_t k = 0; k < o.seeds; ++k) s += r.at(a, 0, k, m);
    return s / static_cast<double>(o.seeds);
  };
  nlohmann::json j;
  j["study"] = "ncs";
  j["experiment"] = "faults";
  j["approach"] = name(o.approach);
  j["scenario"] = o.scenario.name;
  j["scenario_description"] = describe(o.scenario);
  j["duration_s"] = o.scenario.duration_s;
  j["seeds"] = o.seeds;
  j["first_seed"] = o.first_seed;
  std::vector<double> clean;
  for (std::size_t k = 0; k < o.seeds; ++k) clean.push_back(r.at(0, 0, k, 0));
  const util::Summary cs = util::summarize(clean);
  j["clean_cost"] = {{"mean", cs.mean}, {"ci95", cs.ci95}};
  std::ostringstream md;
  md << "Approach " << name(o.approach) << ", scenario " << o.scenario.name << " (" << describe(o.scenario) << "), "
     << o.scenario.duration_s << " s per run, " << o.seeds << " seeds from " << o.first_seed << "; clean cost J = "
     << fmt("%.5g", cs.mean) << " ± " << fmt("%.2g", cs.ci95) << ".\n\n"
     << "| fault | spec | node | what happens | counters per run (faulted − clean) | injected per run | "
        "J fault / J clean (95 % CI) | non-finite runs | live J / engine J |\n"
        "|---|---|---|---|---|---|---|---|---|\n";
  for (std::size_t c = 0; c < cases.size(); ++c) {
    const std::size_t a = c + 1;
    std::vector<double> ratio;
    std::size_t non_finite = 0;
    std::size_t lost = 0;  // runs costing more than 3× the clean run of their seed
    for (std::size_t k = 0; k < o.seeds; ++k) {
      const double f = r.at(a, 0, k, 0);
      if (!std::isfinite(f)) {
        ++non_finite;
      } else if (clean[k] > 0) {
        ratio.push_back(f / clean[k]);
        if (ratio.back() > 3) ++lost;
      }
    }
    const util::Summary rs = util::summarize(ratio);
    nlohmann::json e = {{"name", cases[c].name}, {"node", cases[c].node}, {"spec", cases[c].spec},
                        {"non_finite_runs", non_finite}, {"injected_per_run", mean_of(a, 1)}};
    e["cost_ratio"] = nullptr;
    if (!ratio.empty()) e["cost_ratio"] = {{"mean", rs.mean}, {"ci95", rs.ci95}, {"n", rs.n}};
    std::string counter_text;
    for (std::size_t m = 0; m < counters.size(); ++m) {
      const double faulted = mean_of(a, m + 2);
      const double base = mean_of(0, m + 2);
      e["counters"][counters[m]] = {{"faulted", faulted}, {"clean", base}};
      if (faulted != base) counter_text += (counter_text.empty() ? "" : ", ") + counters[m] + " " + fmt("%+.3g", faulted - base);
    }
    // What happens, from the figures: a poisoned loop (non-finite cost), a lost one (over 3×
    // the clean cost of its seed), absorbed (the interval's upper end within 1 %, or the
    // interval holding 1), else degraded.
    std::string what;
    if (non_finite > 0) {
      what = "loop poisoned: non-finite cost in " + std::to_string(non_finite) + " runs";
    } else if (lost > 0) {
      what = "loop lost: J > 3× clean in " + std::to_string(lost) + " runs";
    } else if (rs.mean + rs.ci95 <= 1.01 || std::fabs(rs.mean - 1) <= rs.ci95) {
      what = "absorbed";
    } else {
      what = "degraded";
    }
    e["runs_over_3x_clean"] = lost;
    e["what_happens"] = what;
    std::string live = "not run";
    if (o.live_duration_s > 0) {
      LiveOptions lo;
      lo.approach = o.approach;
      lo.scenario = o.scenario;
      lo.scenario.duration_s = o.live_duration_s;
      lo.seed = o.first_seed;
      lo.inject = cases[c].spec;
      lo.out_dir = (std::filesystem::path(o.out_dir) / ("live-" + std::to_string(c + 1))).string();
      lo.executable = o.executable;
      try {
        const nlohmann::json lj = run_live(lo);
        const double ratio_live = lj.at("live_cost").get<double>() / lj.at("simulated_cost").get<double>();
        e["live"] = {{"dir", lo.out_dir}, {"live_cost", lj.at("live_cost")}, {"engine_cost", lj.at("simulated_cost")},
                     {"live_over_engine", ratio_live}, {"node_counters", lj.value("node_counters", nlohmann::json::object())}};
        live = fmt("%.3g", ratio_live);
      } catch (const std::exception& ex) {
        e["live"] = {{"dir", lo.out_dir}, {"failed", ex.what()}};
        const bool non_finite_live = std::string(ex.what()).find("not a finite number") != std::string::npos;
        live = non_finite_live ? "failed: non-finite cost" : "failed (see JSON)";
      }
    }
    md << "| " << cases[c].name << " | `" << cases[c].spec << "` | " << cases[c].node << " | " << what << " | "
       << (counter_text.empty() ? "—" : counter_text) << " | " << fmt("%.3g", mean_of(a, 1)) << " | "
       << (ratio.empty() ? std::string("—") : fmt("%.4g", rs.mean) + " ± " + fmt("%.2g", rs.ci95)) << " | " << non_finite
       << "/" << o.seeds << " | " << live << " |\n";
    j["cases"].push_back(e);
  }
  j["markdown"] = md.str();
  if (!o.out_dir.empty()) {
    util::make_directory(o.out_dir);
    std::ofstream((std::filesystem::path(o.out_dir) / "faults.md").string()) << md.str();
  }
  return j;
}

}  // namespace oneshot::ncs

namespace oneshot::sim {

void add_ncs_faults_command(CLI::App* study) {
  auto o = std::make_shared<ncs::FaultTableOptions>();
  auto approach = std::make_shared<std::string>("AK");
  auto scenario = std::make_shared<std::string>("a0.2-T2-d14-s1");
  auto duration = std::make_shared<double>(10);
  auto plant = std::make_shared<std::string>();
  auto json = std::make_shared<std::string>();
  auto cases = std::make_shared<std::vector<std::string>>();
  o->out_dir = "out/ncs-faults";
  CLI::App* cmd = study->add_subcommand(
      "faults", "The fault table of docs/faults.md: each fault against each node, clean and faulted on the same seeds");
  cmd->add_option("--approach", *approach, "approach under test")->capture_default_str();
  cmd->add_option("--scenario", *scenario, "scenario name (the ten of the brief)")->capture_default_str();
  cmd->add_option("--duration", *duration, "seconds per engine run")->check(CLI::Range(0.5, 3600.0))->capture_default_str();
  cmd->add_option("--seeds", o->seeds, "seeds")->check(CLI::Range(2, 100000))->capture_default_str();
  cmd->add_option("--seed", o->first_seed, "first seed")->capture_default_str();
  cmd->add_option("--threads", o->threads, "worker threads (0: every core)")->capture_default_str();
  cmd->add_option("--case", *cases, "a row NAME=NODE=SPEC instead of the defaults (repeatable)");
  cmd->add_option("--live", o->live_duration_s, "seconds of one live run per row (0: none)")->check(CLI::Range(0.0, 600.0))
      ->capture_default_str();
  cmd->add_option("--plant", *plant, "plant file (default: lut_gen/plants/networked_board.json)")->check(CLI::ExistingFile);
  cmd->add_option("--out", o->out_dir, "output directory (faults.md, live runs)")->capture_default_str();
  cmd->add_option("--json", *json, "write the result as JSON to PATH, or '-' for standard output");
  cmd->callback([o, approach, scenario, duration, plant, json, cases]() {
    o->approach = ncs::parse_approach(*approach);
    bool found = false;
    for (const auto& s : ncs::default_scenarios()) {
      if (s.name == *scenario) {
        o->scenario = s;
        found = true;
      }
    }
    if (!found) throw std::invalid_argument("ncs faults: unknown scenario '" + *scenario + "'");
    o->scenario.duration_s = *duration;
    o->cases.clear();
    for (const std::string& c : *cases) {
      const auto a = c.find('=');
      const auto b = a == std::string::npos ? a : c.find('=', a + 1);
      if (b == std::string::npos) throw std::invalid_argument("ncs faults: --case '" + c + "' is not NAME=NODE=SPEC");
      o->cases.push_back({c.substr(0, a), c.substr(a + 1, b - a - 1), c.substr(b + 1)});
    }
    std::error_code ec;
    o->executable = std::filesystem::read_symlink("/proc/self/exe", ec).string();
    const auto ctx = ncs::Context::load_board(*plant);
    const nlohmann::json j = ncs::fault_table(*ctx, *o);
    if (*json != "-") std::cout << j.at("markdown").get<std::string>() << "written to " << o->out_dir << "/faults.md\n";
    if (!json->empty()) util::write_json(*json, j);
  });
}

}  // namespace oneshot::sim
