/// @file study_ncs_sweep.cpp
/// @brief The sweep and summary of `oneshot-sim study run` (see study_ncs_sweep.hpp).
#include "study_ncs_sweep.hpp"

#include <array>

#include "ncs_experiments.hpp"
#include "ncs_loop.hpp"

namespace oneshot::study {
namespace {

/// The node that receives on leg `link`.
const char* receiver(const std::string& link) {
  if (link == "as") return "sensor";
  if (link == "sc") return "controller";
  return "actuator";
}

/// sent, delivered, lost, late, refused of `link` in run `r` of approach `a`.
std::array<double, 5> link_counts(const ncs::RunResult& r, ncs::Approach a, const std::string& link) {
  std::array<double, 5> v{};
  for (const auto& [nm, st] : r.links) {
    if (nm != link) continue;
    v[0] = static_cast<double>(st.sent);
    v[1] = static_cast<double>(st.sent - st.lost);
    v[2] = static_cast<double>(st.lost);
  }
  const std::vector<std::string> names = ncs::counter_names(a);
  const std::string node = receiver(link);
  for (std::size_t i = 0; i < names.size() && i < r.counters.size(); ++i) {
    const std::string& c = names[i];
    if (c.rfind(node + ".", 0) != 0) continue;
    const std::string what = c.substr(node.size() + 1);
    if (what == "stale" || what == "late") v[3] += r.counters[i];
    if (what == "malformed" || what.rfind("refused_", 0) == 0) v[4] += r.counters[i];
  }
  return v;
}

}  // namespace

engine::SweepResults run_ncs_sweep(const NcsStudy& s, std::size_t seeds, unsigned threads, const engine::Shard& shard) {
  engine::SweepSpec spec;
  spec.study = "study";
  spec.experiment = "run";
  for (ncs::Approach a : s.approaches) spec.approaches.emplace_back(ncs::name(a));
  nlohmann::json sc = nlohmann::json::array();
  for (const ncs::Scenario& x : s.scenarios) {
    spec.scenarios.push_back(x.name);
    nlohmann::json legs = nlohmann::json::object();
    for (const auto& [nm, l] : x.legs) {
      legs[nm] = {{"delay", l.delay.describe()}, {"loss", l.loss.describe()}, {"order", l.fifo ? "fifo" : "any"}};
    }
    sc.push_back({{"name", x.name}, {"amplitude_volts", x.amplitude_volts}, {"period_s", x.period_s},
                  {"max_delay_ms", x.max_delay_ms}, {"noise_scale", x.noise_scale}, {"duration_s", x.duration_s},
                  {"s_plus_mean_tau_io_us", s.ctx->mean_tau_io_us(x)}, {"legs", legs}});
  }
  spec.first_seed = s.first_seed;
  spec.seeds = seeds == 0 ? s.seeds : seeds;
  spec.metrics = {"cost", "late", "saturated", "faults"};
  for (const std::string& l : s.links)
    for (const char* c : kLinkCounters) spec.metrics.push_back(l + "." + c);
  spec.config = {{"study_file", s.source},
                 {"plant", s.ctx->plant().name},
                 {"plant_source", s.ctx->plant().source},
                 {"noise_free", false},
                 {"links", s.links},
                 {"compute_us", {s.ctx->timing().compute_min_us, s.ctx->timing().compute_max_us}},
                 {"scenarios", sc}};
  const NcsStudy* study = &s;
  return engine::run_sweep(
      spec, shard, threads,
      [study](std::size_t a, std::size_t k, std::uint64_t seed) {
        const ncs::Approach ap = study->approaches[a];
        const ncs::RunResult r = ncs::run(*study->ctx, ap, study->scenarios[k], seed, ncs::RunOptions{});
        std::vector<double> v{r.cost, static_cast<double>(r.late), static_cast<double>(r.saturated),
                              static_cast<double>(r.faults)};
        for (const std::string& l : study->links) {
          const auto c = link_counts(r, ap, l);
          v.insert(v.end(), c.begin(), c.end());
        }
        return v;
      },
      "study run");
}

nlohmann::json run_outputs(const engine::SweepResults& results, const std::string& out_dir, bool plots) {
  nlohmann::json j = ncs::table_outputs(results, out_dir, plots);
  const engine::SweepSpec& spec = results.spec;
  j["experiment"] = "study run";
  j["study_file"] = spec.config.at("study_file");
  for (std::size_t a = 0; a < spec.approaches.size(); ++a) {
    for (const auto& l : spec.config.at("links")) {
      const std::string link = l.get<std::string>();
      nlohmann::json e = nlohmann::json::object();
      for (const char* c : kLinkCounters) {
        const std::size_t m = results.metric(link + "." + c);
        double total = 0;
        for (std::size_t s = 0; s < spec.scenarios.size(); ++s)
          for (std::size_t k = 0; k < spec.seeds; ++k) total += results.at(a, s, k, m);
        e[c] = total;
      }
      j["links"][spec.approaches[a]][link] = e;
    }
  }
  return j;
}

}  // namespace oneshot::study
