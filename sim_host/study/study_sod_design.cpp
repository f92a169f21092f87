/// @file study_sod_design.cpp
/// @brief A "study": "sod" file's δt design, the settings of its runs, and the sod section that
///        `study check` adds and prints (see study_sod_study.hpp, study_sod_runner.hpp).
#include <array>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "oneshot/engine/json_fields.hpp"
#include "oneshot/util/statistics.hpp"
#include "study_sod_runner.hpp"
#include "study_sod_study.hpp"

namespace oneshot::study {

SodDesigns sod_designs(const SodStudy& s, std::size_t seeds, unsigned threads) {
  const std::size_t count = seeds == 0 ? s.seeds : seeds;
  SodDesigns d;
  d.n_t.assign(s.approaches.size(), std::vector<std::array<std::uint32_t, sod::kNodes>>(s.scenarios.size(), {0, 0}));
  // ΔT_i per (amplitude, steps): lossless plain SOD, N T / packets_i, mean over the seeds (sod E1).
  std::vector<std::pair<std::pair<double, std::int64_t>, std::array<double, sod::kNodes>>> gaps;
  const auto mean_gap = [&](const SodScenario& x) {
    for (const auto& g : gaps)
      if (g.first.first == x.amplitude && g.first.second == x.steps) return g.second;
    engine::SweepSpec spec;
    spec.study = "sod";
    spec.experiment = "mean-gap";
    spec.approaches = {"sod"};
    spec.scenarios = {"dy"};
    spec.first_seed = s.first_seed;
    spec.seeds = count;
    spec.metrics = {"gap1", "gap2"};
    sod::RunConfig cfg;
    cfg.sender = sod::SenderKind::kSod;
    cfg.delta_y[0] = s.delta_y[0];
    cfg.delta_y[1] = s.delta_y[1];
    cfg.amplitude = x.amplitude;
    cfg.steps = x.steps;
    const double duration = static_cast<double>(x.steps) * s.model.period_s();
    const engine::SweepResults r = engine::run_sweep(spec, engine::Shard{}, threads,
        [&](std::size_t, std::size_t, std::uint64_t seed) {
          const sod::RunResult m = sod::simulate_run(s.model, cfg, seed);
          return std::vector<double>{duration / m.sends[0], duration / m.sends[1]};
        }, "study sod dt design");
    std::array<double, sod::kNodes> g{};
    for (std::size_t i = 0; i < sod::kNodes; ++i) {
      std::vector<double> v;
      for (std::size_t k = 0; k < count; ++k) v.push_back(r.at(0, 0, k, i));
      g[i] = util::summarize(v).mean;
    }
    gaps.push_back({{x.amplitude, x.steps}, g});
    return g;
  };
  for (std::size_t a = 0; a < s.approaches.size(); ++a) {
    if (s.approaches[a].sender != sod::SenderKind::kModifiedSod) continue;
    for (std::size_t x = 0; x < s.scenarios.size(); ++x) {
      if (s.n_t_given) {
        d.n_t[a][x] = s.n_t;
        continue;
      }
      if (s.scenarios[x].loss <= 0) continue;  // no loss: no time rule (as `sod table`)
      const std::array<double, sod::kNodes> g = mean_gap(s.scenarios[x]);
      sod::DesignInputs in;
      for (std::size_t i = 0; i < sod::kNodes; ++i) {
        in.delta_y[i] = s.delta_y[i];
        in.loss[i] = s.scenarios[x].loss;
        in.mean_gap_s[i] = g[i];
      }
      in.mu = s.approaches[a].mu;
      sod::DeltaTDesign r;
      try {
        r = sod::design_delta_t(s.model, in);
      } catch (const std::exception& e) {  // the plant's prior Riccati equation: one line naming the plant
        throw engine::InputError(s.source + ": field 'plant.file': the dt design of " + s.approaches[a].name + " on " + s.scenarios[x].name +
                         " failed (" + e.what() + "); give nodes[].trigger.time_steps to run msod without it");
      }
      nlohmann::json e = {{"approach", s.approaches[a].name}, {"scenario", s.scenarios[x].name}, {"loss", s.scenarios[x].loss},
                          {"mu", in.mu}, {"mean_gap_s", {g[0], g[1]}}, {"p0_diag", {r.p0_diag[0], r.p0_diag[1]}},
                          {"p_diag", {r.p_diag[0], r.p_diag[1]}}, {"active_constraints", r.active}};
      for (std::size_t i = 0; i < sod::kNodes; ++i) {
        d.n_t[a][x][i] = r.node[i].bounded ? r.node[i].n_t : 0;
        e["n_t"].push_back(d.n_t[a][x][i]);
        e["delta_t_s"].push_back(r.node[i].bounded ? nlohmann::json(r.node[i].delta_t_s) : nlohmann::json(nullptr));
        e["unbounded_reason"].push_back(r.node[i].bounded ? nlohmann::json(nullptr) : nlohmann::json(r.node[i].reason));
      }
      d.json.push_back(e);
    }
  }
  return d;
}

sod::RunConfig sod_run_config(const SodStudy& s, const SodDesigns& d, std::size_t a, std::size_t x) {
  const SodApproach& p = s.approaches[a];
  const SodScenario& c = s.scenarios[x];
  sod::RunConfig cfg;
  cfg.sender = p.sender;
  cfg.filter = p.filter;
  for (std::size_t i = 0; i < sod::kNodes; ++i) {
    cfg.delta_y[i] = s.delta_y[i];
    cfg.n_t[i] = d.n_t[a][x][i];
    cfg.every[i] = p.every;
  }
  cfg.loss = c.loss;
  cfg.amplitude = c.amplitude;
  cfg.steps = c.steps;
  return cfg;
}

nlohmann::json sod_run_json(const sod::RunConfig& c) {
  const char* sender = c.sender == sod::SenderKind::kSod ? "sod" : c.sender == sod::SenderKind::kModifiedSod ? "msod" : "periodic";
  nlohmann::json j = {{"sender", sender}, {"filter", c.filter == sod::FilterKind::kHeld ? "held" : "predict-only"},
                      {"loss", c.loss}, {"amplitude", c.amplitude}, {"steps", c.steps}};
  if (c.sender != sod::SenderKind::kPeriodic) j["delta_y"] = {c.delta_y[0], c.delta_y[1]};
  if (c.sender == sod::SenderKind::kModifiedSod) j["n_t"] = {c.n_t[0], c.n_t[1]};
  if (c.sender == sod::SenderKind::kPeriodic) j["every"] = c.every[0];
  return j;
}

void add_sod_design(nlohmann::json& r, const SodStudy& s) {
  const sod::SodModel& m = s.model;
  nlohmann::json d;
  d["plant"] = {{"name", m.plant_name}, {"file", s.plant_path}, {"period_us", m.period_us}};
  nlohmann::json ad, qd, c;
  for (std::size_t i = 0; i < sod::kStates; ++i) {
    ad.push_back({m.a_d(i, 0), m.a_d(i, 1)});
    qd.push_back({m.q_d(i, 0), m.q_d(i, 1)});
    c.push_back({m.c(i, 0), m.c(i, 1)});
  }
  d["A_d"] = ad;
  d["B_d"] = {{m.b_d(0, 0)}, {m.b_d(1, 0)}};
  d["Q_d"] = qd;
  d["C"] = c;
  d["R_diag"] = {m.r_diag[0], m.r_diag[1]};
  for (std::size_t i = 0; i < sod::kNodes; ++i)
    d["sensors"].push_back({{"node", s.sensors[i]}, {"output", i + 1}, {"link", s.links[i]}, {"delta_y", s.delta_y[i]},
                            {"streams", "measurement/node" + std::to_string(i + 1) + ", link/node" + std::to_string(i + 1) + "/loss"}});
  d["estimator"] = s.estimator;
  d["n_t"] = s.n_t_given ? nlohmann::json({{"given", {s.n_t[0], s.n_t[1]}}})
                         : nlohmann::json({{"design", "dt* of the section-5 design at xi of each scenario (0 at xi = 0), "
                                                      "Delta_T measured over the seeds of the run"}, {"seeds", s.seeds}});
  const SodDesigns designs = sod_designs(s, 0, 0);
  d["designs"] = designs.json;
  for (std::size_t a = 0; a < s.approaches.size(); ++a) {
    nlohmann::json e = {{"name", s.approaches[a].name}, {"kind", s.approaches[a].kind}};
    e["per_scenario"] = nlohmann::json::array();
    for (std::size_t x = 0; x < s.scenarios.size(); ++x) e["per_scenario"].push_back(sod_run_json(sod_run_config(s, designs, a, x)));
    d["approaches"].push_back(e);
  }
  r["sod"] = d;
}

std::string describe_sod(const nlohmann::json& r) {
  const nlohmann::json& d = r.at("sod");
  std::ostringstream o;
  o << "sod estimation: plant " << d.at("plant").at("name").get<std::string>() << " (T = " << d.at("plant").at("period_us")
    << " us), A_d = " << d.at("A_d").dump() << ", B_d = " << d.at("B_d").dump() << ", Q_d = " << d.at("Q_d").dump()
    << ", C = " << d.at("C").dump() << ", R = diag " << d.at("R_diag").dump() << "\n";
  for (const nlohmann::json& n : d.at("sensors"))
    o << "  sensor " << n.at("node").get<std::string>() << " reads y" << n.at("output") << ", dy = " << n.at("delta_y") << ", link "
      << n.at("link").get<std::string>() << " (streams " << n.at("streams").get<std::string>() << ")\n";
  o << "  estimator " << d.at("estimator").get<std::string>() << "\n";
  if (d.at("n_t").contains("given")) o << "  msod n_t given: " << d.at("n_t").at("given").dump() << "\n";
  for (const nlohmann::json& e : d.at("designs"))
    o << "  dt design " << e.at("approach").get<std::string>() << " on " << e.at("scenario").get<std::string>() << " (xi = " << e.at("loss")
      << ", mu = " << e.at("mu") << ", Delta_T = " << e.at("mean_gap_s").dump() << " s over " << d.at("n_t").value("seeds", 0)
      << " seeds): P0 diag " << e.at("p0_diag").dump() << ", dt* = " << e.at("delta_t_s").dump() << " s, n_t = " << e.at("n_t").dump()
      << "\n";
  for (const nlohmann::json& a : d.at("approaches")) {
    const nlohmann::json& c = a.at("per_scenario").empty() ? nlohmann::json::object() : a.at("per_scenario").at(0);
    o << "  approach " << a.at("name").get<std::string>() << " (" << a.at("kind").get<std::string>() << "): sender "
      << c.value("sender", "") << ", filter " << c.value("filter", "");
    if (c.contains("every")) o << ", every " << c.at("every");
    o << "\n";
  }
  return o.str();
}

}  // namespace oneshot::study
