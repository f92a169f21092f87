/// @file petc_experiments.cpp
/// @brief The petc study's sweeps (cases, GPI surface) and traces, with their files.
#include "petc_experiments.hpp"

#include <cmath>
#include <sstream>
#include <stdexcept>

#include "oneshot/engine/sweep_statistics.hpp"
#include "oneshot/util/number_text.hpp"
#include "oneshot/util/output_files.hpp"
#include "oneshot/sim/sweep_faults.hpp"

namespace oneshot::sim::petc {

namespace {

std::string fmt(double x, int digits = 4) { return util::format_g(x, digits); }

std::vector<double> log_grid(double lo, double hi, std::size_t n) {
  std::vector<double> v;
  for (std::size_t i = 0; i < n; ++i)
    v.push_back(n == 1 ? lo : std::pow(10.0, std::log10(lo) + (std::log10(hi) - std::log10(lo)) * static_cast<double>(i) /
                                                                    static_cast<double>(n - 1)));
  return v;
}

engine::SweepResults finish(const engine::SweepSpec& spec, const SweepOptions& opt, const engine::RunFunction& run,
                            const std::string& label) {
  if (opt.seeds < 2) throw std::invalid_argument("petc: --seeds must be at least 2 for confidence intervals");
  return engine::run_sweep(spec, opt.shard, opt.threads, run, label);
}

}  // namespace

nlohmann::json setup_config(const PetcSetup& s) {
  return {{"plant", s.plant.file.name},
          {"steps", s.opt.steps},
          {"ratio", s.opt.ratio},
          {"horizon", kHorizon},
          {"sample_at_update", s.opt.sample_at_update},
          {"noise_accumulation", s.opt.frozen_noise ? "frozen (printed eq. 13)" : "sum (W_e(N))"},
          {"dob_cutoff_hz", s.opt.dob_cutoff_hz},
          {"sigma_w", std::sqrt(s.plant.augmented.w)},
          {"sigma_v", std::sqrt(s.plant.augmented.v)},
          {"reference", s.opt.reference},
          {"cs", s.mrci.cs},
          {"ise", s.ise},
          {"plant_only_w", s.plant_only.w},
          {"eso_w", s.eso.w}};
}

nlohmann::json run_table(const PetcSetup& setup, const SweepOptions& opt) {
  const std::vector<CaseSpec> cases = default_cases();
  engine::SweepSpec spec;
  spec.study = "petc";
  spec.experiment = "table";
  for (const CaseSpec& c : cases) spec.approaches.push_back(c.name);
  spec.scenarios = {"unit-step"};
  spec.first_seed = opt.first_seed;
  spec.seeds = opt.seeds;
  spec.metrics = metric_names();
  spec.config = setup_config(setup);
  nlohmann::json labels = nlohmann::json::object();
  for (const CaseSpec& c : cases)
    labels[c.name] = {{"label", c.label}, {"sigma_s", c.sigma_s}, {"delta_s", c.delta_s}, {"sigma_c", c.sigma_c},
                      {"delta_c", c.delta_c}, {"noise", c.noise}};
  spec.config["cases"] = labels;
  sim::add_fault_metrics(spec, opt.faults, "tracking error sqrt(sum_k (r - y_k)^2)");
  util::make_directory(opt.out_dir);
  const engine::SweepResults r = finish(
      spec, opt,
      [&](std::size_t a, std::size_t, std::uint64_t seed) {
        if (opt.faults.empty()) return run_case(setup, cases[a], seed);
        FaultRun f, clean;
        f.spec = opt.faults;
        std::vector<double> v = run_case(setup, cases[a], seed, nullptr, &f);
        static_cast<void>(run_case(setup, cases[a], seed, nullptr, &clean));  // the same seed without faults
        f.counts.ratio_to_clean = f.tracking_error / clean.tracking_error;
        sim::append_fault_values(v, f.counts);
        return v;
      },
      "petc table");
  if (!opt.shard.whole()) return engine::write_shard_file(r, opt.out_dir, "table", opt.shard);
  return table_outputs(r, opt.out_dir, opt.plots);
}

nlohmann::json table_outputs(const engine::SweepResults& r, const std::string& out_dir, bool /*plots*/) {
  util::make_directory(out_dir);
  const engine::SweepSpec& spec = r.spec;
  std::vector<engine::SweepSummary> sums;
  for (std::size_t m = 0; m < spec.metrics.size(); ++m) sums.push_back(engine::summarize_metric(r, m, 0));
  nlohmann::json cases = nlohmann::json::array();
  for (std::size_t a = 0; a < spec.approaches.size(); ++a) {
    nlohmann::json metrics = nlohmann::json::object();
    for (std::size_t m = 0; m < spec.metrics.size(); ++m) metrics[spec.metrics[m]] = util::mean_ci_json(sums[m].value[a]);
    nlohmann::json c = {{"case", spec.approaches[a]}, {"metrics", metrics}};
    if (spec.config.contains("cases")) c["setting"] = spec.config["cases"].at(spec.approaches[a]);
    if (spec.config.contains("inject")) c["faults"] = sim::fault_row(r, a, 0);
    cases.push_back(c);
  }
  // Paired differences (same seeds) between consecutive cases for the headline metrics.
  nlohmann::json paired = nlohmann::json::object();
  for (const char* name : {"U_c", "U_a", "N_E", "GPI"}) {
    const engine::SweepSummary& sm = sums[r.metric(name)];
    nlohmann::json pm = nlohmann::json::object();
    for (const auto& p : sm.paired)
      if (p.b == p.a + 1) pm[spec.approaches[p.b] + " - " + spec.approaches[p.a]] = {{"mean", -p.diff.mean}, {"ci95", p.diff.ci95}};
    paired[name] = pm;
  }
  write_runs_csv(r, util::path_in(out_dir, "table_runs.csv"));
  nlohmann::json j = {{"study", "petc"},        {"experiment", "table"},     {"seeds", spec.seeds},
                      {"first_seed", spec.first_seed}, {"n_tts", spec.config.value("steps", 0)},
                      {"config", spec.config},  {"cases", cases},          {"paired_differences_consecutive", paired}};
  if (spec.config.contains("inject")) {
    j["inject"] = spec.config.at("inject");
    j["markdown_faults"] = sim::fault_markdown(r);
  }
  util::write_json(util::path_in(out_dir, "table.json"), j);
  return j;
}

std::string table_markdown(const nlohmann::json& t) {
  std::ostringstream o;
  auto cell = [](const nlohmann::json& m, const char* k, int d = 3) {
    return fmt(m.at(k).at("mean").get<double>(), d) + " ± " + fmt(m.at(k).at("ci95").get<double>(), 2);
  };
  o << "| case | setting | U_c (N_sc) | U_a (N_ca) | C_c | N_E | GPI | longest silence s / a | safety s / c | N_max | "
       "multiply-adds / run | max per arrival | rms(d − d̂) |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const auto& c : t.at("cases")) {
    const auto& m = c.at("metrics");
    o << "| " << c.at("case").get<std::string>() << " | "
      << (c.contains("setting") ? c["setting"].at("label").get<std::string>() : "") << " | " << cell(m, "U_c") << " ("
      << fmt(m.at("sensor_packets").at("mean").get<double>()) << ") | " << cell(m, "U_a") << " ("
      << fmt(m.at("actuator_packets").at("mean").get<double>()) << ") | " << cell(m, "C_c") << " | "
      << cell(m, "N_E") << " | " << cell(m, "GPI") << " | " << fmt(m.at("longest_silence_sensor").at("mean").get<double>())
      << " / " << fmt(m.at("longest_silence_actuator").at("mean").get<double>()) << " | "
      << fmt(m.at("sensor_safety_fires").at("mean").get<double>()) << " / "
      << fmt(m.at("controller_safety_fires").at("mean").get<double>()) << " | "
      << fmt(m.at("N_max").at("mean").get<double>()) << " | " << fmt(m.at("macs").at("mean").get<double>(), 3) << " | "
      << fmt(m.at("macs_max_arrival").at("mean").get<double>(), 3) << " | " << cell(m, "d_error_rms", 3) << " |\n";
  }
  return o.str();
}

nlohmann::json run_gpi(const PetcSetup& setup, const SweepOptions& opt, std::size_t grid) {
  if (grid < 2 || grid > 20) throw std::invalid_argument("petc gpi: --grid must lie in 2 … 20");
  const std::vector<double> ss = log_grid(1e-8, 1e-3, grid);
  const std::vector<double> cc = log_grid(1e-5, 1e-1, grid);
  const CaseSpec base = default_cases()[3];  // case 4: noise, known-model disturbance
  std::vector<CaseSpec> cases;
  engine::SweepSpec spec;
  spec.study = "petc";
  spec.experiment = "gpi";
  nlohmann::json points = nlohmann::json::array();
  for (std::size_t i = 0; i < grid; ++i)
    for (std::size_t j = 0; j < grid; ++j) {
      CaseSpec c = base;
      c.sigma_s = c.delta_s = ss[i];
      c.sigma_c = c.delta_c = cc[j];
      c.name = "s" + std::to_string(i) + "c" + std::to_string(j);
      cases.push_back(c);
      spec.approaches.push_back(c.name);
      points.push_back({{"name", c.name}, {"sigma_s", ss[i]}, {"sigma_c", cc[j]}});
    }
  spec.scenarios = {"unit-step"};
  spec.first_seed = opt.first_seed;
  spec.seeds = opt.seeds;
  spec.metrics = metric_names();
  spec.config = setup_config(setup);
  spec.config["grid"] = points;
  util::make_directory(opt.out_dir);
  const engine::SweepResults r = finish(
      spec, opt, [&](std::size_t a, std::size_t, std::uint64_t seed) { return run_case(setup, cases[a], seed); },
      "petc gpi");
  if (!opt.shard.whole()) return engine::write_shard_file(r, opt.out_dir, "gpi", opt.shard);
  return gpi_outputs(r, opt.out_dir, opt.plots);
}

nlohmann::json gpi_outputs(const engine::SweepResults& r, const std::string& out_dir, bool plots) {
  util::make_directory(out_dir);
  const engine::SweepSpec& spec = r.spec;
  const nlohmann::json& grid = spec.config.at("grid");
  const std::size_t na = spec.approaches.size();
  const engine::SweepSummary gpi = engine::summarize_metric(r, r.metric("GPI"), 0);
  const engine::SweepSummary uc = engine::summarize_metric(r, r.metric("U_c"), 0);
  const engine::SweepSummary ua = engine::summarize_metric(r, r.metric("U_a"), 0);
  const engine::SweepSummary ne = engine::summarize_metric(r, r.metric("N_E"), 0);
  const engine::SweepSummary nsc = engine::summarize_metric(r, r.metric("sensor_packets"), 0);
  const engine::SweepSummary nca = engine::summarize_metric(r, r.metric("actuator_packets"), 0);
  // Pareto front on (traffic U_c + U_a, N_E) of the means: no other point at most as bad in
  // both and better in one.
  std::vector<bool> front(na, true);
  for (std::size_t a = 0; a < na; ++a)
    for (std::size_t b = 0; b < na && front[a]; ++b) {
      const double ta = uc.value[a].mean + ua.value[a].mean, tb = uc.value[b].mean + ua.value[b].mean;
      const double ea = ne.value[a].mean, eb = ne.value[b].mean;
      if (b != a && tb <= ta && eb <= ea && (tb < ta || eb < ea)) front[a] = false;
    }
  nlohmann::json pts = nlohmann::json::array();
  std::vector<std::vector<double>> rows;
  std::size_t best = 0;
  for (std::size_t a = 0; a < na; ++a) {
    if (gpi.value[a].mean < gpi.value[best].mean) best = a;
    const double s = grid.at(a).at("sigma_s"), c = grid.at(a).at("sigma_c");
    pts.push_back({{"sigma_s", s}, {"sigma_c", c}, {"GPI", util::mean_ci_json(gpi.value[a])}, {"U_c", util::mean_ci_json(uc.value[a])},
                   {"U_a", util::mean_ci_json(ua.value[a])}, {"N_E", util::mean_ci_json(ne.value[a])},
                   {"sensor_packets", nsc.value[a].mean}, {"actuator_packets", nca.value[a].mean},
                   {"pareto", static_cast<bool>(front[a])}});
    rows.push_back({s, c, gpi.value[a].mean, gpi.value[a].ci95, uc.value[a].mean, ua.value[a].mean, ne.value[a].mean,
                    front[a] ? 1.0 : 0.0});
  }
  util::write_csv(util::path_in(out_dir, "gpi.csv"), {"sigma_s", "sigma_c", "gpi", "gpi_ci95", "u_c", "u_a", "n_e", "pareto"}, rows);
  write_runs_csv(r, util::path_in(out_dir, "gpi_runs.csv"));
  nlohmann::json j = {{"study", "petc"}, {"experiment", "gpi"}, {"seeds", spec.seeds}, {"weights", {0.45, 0.45, 0.1}},
                      {"setting", "case 4 (noise, known-model disturbance); delta = sigma on both links"},
                      {"points", pts}, {"best", pts.at(best)}};
  util::write_json(util::path_in(out_dir, "gpi.json"), j);
  if (plots) {
    std::ostringstream g;
    g << util::gnuplot_png_terminal(1100, 700) << "set output 'gpi.png'\nset multiplot layout 1,2\n"
      << "set title 'GPI = 0.45 U_c + 0.45 U_a + 0.1 N_E (mean over seeds)'\nset xlabel 'log10 sigma_s = delta_s'\n"
      << "set ylabel 'log10 sigma_c = delta_c'\nset view map\nset datafile separator ','\n"
      << "plot 'gpi.csv' every ::1 using (log10($1)):(log10($2)):3 with points pt 5 ps 4 palette notitle\n"
      << "set title 'Pareto front: traffic vs N_E'\nset xlabel 'U_c + U_a'\nset ylabel 'N_E'\nset logscale y\n"
      << "plot 'gpi.csv' every ::1 using ($5+$6):7 with points pt 7 title 'grid', "
      << "'gpi.csv' every ::1 using ($8 > 0 ? $5+$6 : 1/0):7 with points pt 6 ps 2 title 'Pareto'\nunset multiplot\n";
    util::run_gnuplot(out_dir, "gpi.gp", g.str());
    j["plots"] = {"gpi.png"};
  }
  return j;
}

nlohmann::json run_traces(const PetcSetup& setup, std::uint64_t seed, const std::string& out_dir, bool plots) {
  util::make_directory(out_dir);
  nlohmann::json j = nlohmann::json::object();
  const std::vector<CaseSpec> cases = default_cases();
  for (std::size_t ci : {std::size_t{3}, std::size_t{4}, std::size_t{5}, std::size_t{6}}) {
    const CaseSpec& c = cases[ci];
    RunTrace t;
    const std::vector<double> v = run_case(setup, c, seed, &t);
    std::string tag = c.name;
    if (tag == "6'") tag = "6p";
    std::vector<std::vector<double>> rows;
    std::size_t arrival = 0;
    for (std::size_t k = 0; k < t.y_true.size(); ++k) {
      double n = 0;
      if (t.sensor_sent[k]) n = arrival < t.multiplicity.size() ? t.multiplicity[arrival++] : 0;
      rows.push_back({static_cast<double>(k), t.y_true[k], t.u[k], t.d[k], t.d_hat[k],
                      static_cast<double>(t.sensor_sent[k]), static_cast<double>(t.actuator_sent[k]), n});
    }
    util::write_csv(util::path_in(out_dir, "trace_case" + tag + ".csv"), {"k", "y", "u", "d", "d_hat", "sensor_sent", "actuator_sent", "N"},
              rows);
    j[c.name] = {{"seed", seed}, {"N_E", v[3]}, {"d_error_rms", v[17]}, {"d_rms", v[18]}, {"N_max", v[12]}};
    if (plots) {
      std::ostringstream g;
      g << util::gnuplot_png_terminal(1100, 700) << "set output 'trace_case" << tag << ".png'\nset datafile separator ','\nset multiplot layout 2,1\n"
        << "set title 'case " << tag << " (" << c.label << "), seed " << seed << ": d and d_hat'\nset xlabel 'k'\n"
        << "plot 'trace_case" << tag << ".csv' every ::1 using 1:4 with lines title 'd', '' every ::1 using 1:5 with "
        << "lines title 'd_hat'\nset title 'multiplicity N at each arrival'\n"
        << "plot 'trace_case" << tag << ".csv' every ::1 using 1:($6 > 0 ? $8 : 1/0) with impulses title 'N'\n"
        << "unset multiplot\n";
      util::run_gnuplot(out_dir, "trace_case" + tag + ".gp", g.str());
    }
  }
  return j;
}

}  // namespace oneshot::sim::petc
