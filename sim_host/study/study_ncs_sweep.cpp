/// @file study_ncs_sweep.cpp
/// @brief The sweep and summary of `oneshot-sim study run` (see study_ncs_sweep.hpp).
#include "study_ncs_sweep.hpp"

#include <array>
#include <optional>
#include <utility>
#include <vector>

#include "ncs_analytic.hpp"
#include "ncs_experiments.hpp"
#include "ncs_loop.hpp"

namespace oneshot::study {
namespace {

/// Positions of the counters in kLinkCounters (and in the metrics of each link).
constexpr std::size_t kSent = link_counter_index("sent");
constexpr std::size_t kDelivered = link_counter_index("delivered");
constexpr std::size_t kLost = link_counter_index("lost");
constexpr std::size_t kLate = link_counter_index("late");
constexpr std::size_t kRefused = link_counter_index("refused");
static_assert(kSent < std::size(kLinkCounters) && kDelivered < std::size(kLinkCounters) &&
                  kLost < std::size(kLinkCounters) && kLate < std::size(kLinkCounters) &&
                  kRefused < std::size(kLinkCounters),
              "every counter link_counts() fills is named in kLinkCounters");

/// Where the receiving node's counters of one link add up: (position in ncs::RunResult::counters,
/// position in kLinkCounters), in the order of ncs::counter_names().
using LinkCounterMap = std::vector<std::pair<std::size_t, std::size_t>>;

/// The map of `link` under approach `a`: the receiving node's stale counter to kLate (frames
/// dropped as stale: not newer than what the node holds, or their period past; the actuator's
/// "late" counts periods without a command, not frames: the approach's late_commands), its
/// malformed and refused_* counters to kRefused (empty when `link` is not a leg of the loop).
LinkCounterMap link_counter_map(ncs::Approach a, const std::string& link) {
  LinkCounterMap m;
  const NcsLeg* leg = find_ncs_leg(link);
  if (leg == nullptr) return m;  // map_ncs_study admits the loop's legs only
  const std::string node = leg->to;  // the receiving node's counters
  const std::vector<std::string> names = ncs::counter_names(a);
  for (std::size_t i = 0; i < names.size(); ++i) {
    const std::string& c = names[i];
    if (c.rfind(node + ".", 0) != 0) continue;
    const std::string what = c.substr(node.size() + 1);
    if (what == "stale") m.emplace_back(i, kLate);
    if (what == "malformed" || what.rfind("refused_", 0) == 0) m.emplace_back(i, kRefused);
  }
  return m;
}

/// The counters of `link` in run `r`, in the order of kLinkCounters; `map` is
/// link_counter_map() of the run's approach and `link`.
std::array<double, std::size(kLinkCounters)> link_counts(const ncs::RunResult& r, const LinkCounterMap& map,
                                                         const std::string& link) {
  std::array<double, std::size(kLinkCounters)> v{};
  for (const auto& [nm, st] : r.links) {
    if (nm != link) continue;
    v[kSent] = static_cast<double>(st.sent);
    v[kDelivered] = static_cast<double>(st.sent - st.lost);
    v[kLost] = static_cast<double>(st.lost);
  }
  for (const auto& [i, slot] : map)
    if (i < r.counters.size()) v[slot] += r.counters[i];
  return v;
}

/// Upper bound of the sc + ca delays of scenario `x` in ms; null when a leg's delay model has
/// no upper bound (Poisson, lognormal, Pareto).
nlohmann::json sc_ca_delay_bound_ms(const ncs::Scenario& x) {
  const std::optional<engine::Duration> ub = ncs::sc_ca_delay_bound(x);
  if (!ub) return nullptr;
  return static_cast<double>(ub->count()) * 1e-6;
}

}  // namespace

engine::SweepResults run_ncs_sweep(const NcsStudy& s, std::size_t seeds, unsigned threads, const engine::Shard& shard,
                                   bool analytic) {
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
                  {"max_delay_ms", x.max_delay_ms}, {"delay_bound_sc_ca_ms", sc_ca_delay_bound_ms(x)},
                  {"noise_scale", x.noise_scale}, {"duration_s", x.duration_s},
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
  if (analytic) {  // only then, as ncs table: the spec stays as it was without
    spec.config["analytic"] = true;
    spec.metrics.insert(spec.metrics.end(), std::begin(ncs::kAnalyticMetrics), std::end(ncs::kAnalyticMetrics));
  }
  // Per approach, per link of the file: where the receiving node's counters go (built once).
  std::vector<std::vector<LinkCounterMap>> maps;
  for (ncs::Approach ap : s.approaches) {
    std::vector<LinkCounterMap>& per_link = maps.emplace_back();
    for (const std::string& l : s.links) per_link.push_back(link_counter_map(ap, l));
  }
  const NcsStudy* study = &s;
  const std::vector<std::vector<LinkCounterMap>>* counter_maps = &maps;
  return engine::run_sweep(
      spec, shard, threads,
      [study, counter_maps, analytic](std::size_t a, std::size_t k, std::uint64_t seed) {
        const ncs::Approach ap = study->approaches[a];
        const ncs::RunResult r = ncs::run(*study->ctx, ap, study->scenarios[k], seed, ncs::RunOptions{});
        std::vector<double> v{r.cost, static_cast<double>(r.late), static_cast<double>(r.saturated),
                              static_cast<double>(r.faults)};
        for (std::size_t l = 0; l < study->links.size(); ++l) {
          const auto c = link_counts(r, (*counter_maps)[a][l], study->links[l]);
          v.insert(v.end(), c.begin(), c.end());
        }
        if (analytic) {  // ncs table --analytic's columns: the same run in analytic mode
          const auto x = ncs::analytic_metrics(*study->ctx, ap, study->scenarios[k], seed, ncs::RunOptions{});
          v.insert(v.end(), x.begin(), x.end());
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
  // ncs table keys S's ratio by study ncs's d, which the file's legs do not have: left out.
  j.erase("S_ratio_to_I_by_delay_ms");
  j.erase("S_ratio_increases_with_delay");
  for (const auto& x : spec.config.at("scenarios")) j["delay_bound_sc_ca_ms"][x.at("name").get<std::string>()] = x.at("delay_bound_sc_ca_ms");
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
