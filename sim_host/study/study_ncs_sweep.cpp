/// @file study_ncs_sweep.cpp
/// @brief The sweep of `oneshot-sim study run` (see study_ncs_sweep.hpp; its summary: study_ncs_summary.cpp).
#include "study_ncs_sweep.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <optional>
#include <utility>
#include <vector>

#include "ncs_analytic.hpp"
#include "ncs_cpu.hpp"
#include "ncs_experiments.hpp"
#include "ncs_cache_pools.hpp"
#include "ncs_loop.hpp"
#include "oneshot/engine/sweep_statistics.hpp"
#include "oneshot/util/statistics.hpp"
#include "study_one_shot_discretizer.hpp"

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
/// malformed, corrupt and refused_* counters to kRefused (empty when `link` is not a leg of the loop).
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
    if (what == "malformed" || what == "corrupt" || what.rfind("refused_", 0) == 0) m.emplace_back(i, kRefused);
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

/// The delay metrics of `leg` in run `r`, in the order of kBusDelayMetrics (0 when the run
/// sent nothing over the bus: I and IK keep their delay-free links).
std::array<double, std::size(kBusDelayMetrics)> bus_delays(const ncs::RunResult& r, const std::string& leg) {
  std::array<double, std::size(kBusDelayMetrics)> v{};
  for (const auto& [nm, st] : r.bus_legs) {
    if (nm != leg) continue;
    v[0] = static_cast<double>(st.delivered);
    v[1] = static_cast<double>(st.min_delay.count()) * 1e-3;
    v[2] = static_cast<double>(st.max_delay.count()) * 1e-3;
    v[3] = static_cast<double>(st.total_delay.count()) * 1e-3;
  }
  return v;
}

/// The CPU metrics of run `r`, in the order of kCpuMetrics.
std::array<double, std::size(kCpuMetrics)> cpu_metrics(const ncs::RunResult& r) {
  const ncs::CpuRunStats& c = r.cpu;
  return {static_cast<double>(c.jobs), static_cast<double>(c.response_min.count()) * 1e-3,
          static_cast<double>(c.response_max.count()) * 1e-3, c.response_sum_us, static_cast<double>(c.deadline_misses),
          static_cast<double>(c.other_misses), static_cast<double>(c.busy.count()) * 1e-3};
}

/// A stepped set-point of scenario `x` for the sweep's configuration: its description, r_0, the
/// number of changes on the kh grid and an FNV-1a hash of their periods and values (shards of
/// files with other steps do not merge).
nlohmann::json setpoint_json(const ncs::Scenario& x) {
  std::uint64_t hash = 14695981039346656037ULL;
  const auto mix = [&hash](std::uint64_t v) {
    for (int b = 0; b < 8; ++b) {
      hash ^= (v >> (8 * b)) & 0xFFU;
      hash *= 1099511628211ULL;
    }
  };
  for (const auto& [k, v] : *x.setpoint_changes) {
    std::uint64_t bits = 0;
    std::memcpy(&bits, &v, sizeof bits);
    mix(k);
    mix(bits);
  }
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(hash));
  return {{"description", x.setpoint_description}, {"r0", x.setpoint_r0}, {"changes", x.setpoint_changes->size()},
          {"changes_fnv1a", hex}};
}

}  // namespace

std::vector<std::string> bus_links(const NcsStudy& s) {
  std::vector<std::string> out;
  if (s.scenarios.empty()) return out;
  for (const std::string& l : s.links)
    if (s.scenarios[0].bus_legs.count(l) != 0) out.push_back(l);
  return out;
}

engine::SweepSpec study_sweep_spec(const NcsStudy& s, std::size_t seeds, const char* experiment) {
  engine::SweepSpec spec;
  spec.study = "study";
  spec.experiment = experiment;
  for (ncs::Approach a : s.approaches) spec.approaches.emplace_back(ncs::name(a));
  for (const ncs::Scenario& x : s.scenarios) spec.scenarios.push_back(x.name);
  spec.first_seed = s.first_seed;
  spec.seeds = seeds == 0 ? s.seeds : seeds;
  return spec;
}

nlohmann::json loop_sweep_config(const NcsStudy& s) {
  nlohmann::json sc = nlohmann::json::array();
  const std::vector<std::string> on_bus = bus_links(s);
  for (std::size_t i = 0; i < s.scenarios.size(); ++i) {
    const ncs::Scenario& x = s.scenarios[i];
    nlohmann::json bus_legs = nlohmann::json::object();
    for (const auto& [nm, b] : x.bus_legs) {
      nlohmann::json wcrt = nullptr;
      if (i < s.bus_response_us.size()) {
        const auto it = s.bus_response_us[i].find(nm);
        if (it != s.bus_response_us[i].end() && it->second) wcrt = *it->second;
      }
      bus_legs[nm] = {{"bus", b.bus.name}, {"bit_rate", b.bus.bit_rate}, {"id", b.id},
                      {"background_streams", b.background.size()}, {"worst_response_us", wcrt}};
    }
    nlohmann::json legs = nlohmann::json::object();
    for (const auto& [nm, l] : x.legs) {
      legs[nm] = {{"delay", l.delay.describe()}, {"loss", l.loss.describe()}, {"order", l.fifo ? "fifo" : "any"}};
    }
    sc.push_back({{"name", x.name}, {"amplitude_volts", x.amplitude_volts}, {"period_s", x.period_s},
                  {"max_delay_ms", x.max_delay_ms}, {"delay_bound_sc_ca_ms", sc_ca_delay_bound_ms(x)},
                  {"noise_scale", x.noise_scale}, {"duration_s", x.duration_s},
                  {"s_plus_mean_tau_io_us", x.bus_legs.empty() ? nlohmann::json(s.ctx->mean_tau_io_us(x)) : nlohmann::json(nullptr)},
                  {"legs", legs}});
    if (!x.bus_legs.empty()) sc.back()["bus_legs"] = bus_legs;
    if (x.setpoint_changes) sc.back()["reference"] = setpoint_json(x);  // only then: square-wave files' specs stay as they were
    if (ncs::has_clock_offsets(x)) {  // likewise: files without clock offsets keep their spec
      sc.back()["clock_offsets_us"] = {{"sensor", x.sensor_clock_us}, {"controller", x.controller_clock_us},
                                       {"actuator", x.actuator_clock_us}};
    }
  }
  nlohmann::json config = {{"study_file", s.source},
                           {"plant", s.ctx->plant().name},
                           {"plant_source", s.ctx->plant().source},
                           {"noise_free", false},
                           {"links", s.links},
                           {"compute_us", {s.ctx->timing().compute_min_us, s.ctx->timing().compute_max_us}},
                           {"scenarios", sc}};
  if (!on_bus.empty()) config["bus_links"] = on_bus;  // only then: the spec of files without stays as it was
  // The one-shot discretizers when one is not "generic" (only then: generic files' specs stay as
  // they were), so shards of files that differ in them never merge.
  nlohmann::json disc = nlohmann::json::object();
  bool tabled = false;
  for (std::size_t i = 0; i < s.discretizations.size() && i < s.approaches.size(); ++i) {
    if (!ncs::one_shot(s.approaches[i])) continue;
    disc[ncs::name(s.approaches[i])] = name(s.discretizations[i].kind);
    tabled = tabled || s.discretizations[i].kind != OneShotDiscretizer::kGeneric;
  }
  if (tabled) config["one_shot_discretizers"] = disc;
  return config;
}

std::vector<std::string> loop_sweep_metrics(const NcsStudy& s) {
  std::vector<std::string> metrics = {"cost", "late", "saturated", "faults"};
  for (const std::string& l : s.links)
    for (const char* c : kLinkCounters) metrics.push_back(l + "." + c);
  for (const std::string& l : bus_links(s))
    for (const char* c : kBusDelayMetrics) metrics.push_back(l + "." + c);
  return metrics;
}

std::vector<double> loop_sweep_values(const NcsStudy& s, std::size_t a, const ncs::RunResult& r, const std::vector<std::string>& on_bus) {
  std::vector<double> v{r.cost, static_cast<double>(r.late), static_cast<double>(r.saturated), static_cast<double>(r.faults)};
  for (const std::string& l : s.links) {
    const auto c = link_counts(r, link_counter_map(s.approaches[a], l), l);
    v.insert(v.end(), c.begin(), c.end());
  }
  for (const std::string& l : on_bus) {
    const auto d = bus_delays(r, l);
    v.insert(v.end(), d.begin(), d.end());
  }
  return v;
}

engine::SweepResults run_ncs_sweep(const NcsStudy& s, std::size_t seeds, unsigned threads, const engine::Shard& shard,
                                   bool analytic, bool share_caches) {
  if (!s.loops.empty()) return run_loops_sweep(s, seeds, threads, shard, analytic, share_caches);  // study_loops_sweep.cpp
  bool one_shot = false;
  for (ncs::Approach a : s.approaches) one_shot = one_shot || ncs::one_shot(a);
  if (analytic && one_shot) {
    throw engine::InputError("field '--analytic': the one-shot approaches (OS, OSp, OSK) have no analytic cost");
  }
  const design::PlantDescription& plant = s.ctx->plant();
  const bool board = s.ctx->board();
  if (analytic && !board) {
    throw engine::InputError("field '--analytic': the analytic tracker is 2-state: it runs the board's plant (n = 2, m = 1, p = 2, C = I) only, not n = " +
                             std::to_string(plant.a.rows));
  }
  if (analytic && !s.scenarios.empty() && ncs::has_clock_offsets(s.scenarios[0])) {
    throw engine::InputError("field '--analytic': the analytic tracker runs the nodes on one clock (nodes[].clock_offset_us 0)");
  }
  const bool sensor_on_cpu = !s.scenarios.empty() && s.scenarios[0].sensor_cpu != nullptr;
  if (analytic && sensor_on_cpu) {
    throw engine::InputError("field '--analytic': no analytic cost with the sensor on a CPU (its samples lag kh by the schedule)");
  }
  engine::SweepSpec spec = study_sweep_spec(s, seeds, "run");
  const std::vector<std::string> on_bus = bus_links(s);
  spec.metrics = loop_sweep_metrics(s);
  const bool on_cpu = !s.scenarios.empty() && s.scenarios[0].controller_cpu != nullptr;
  if (on_cpu)
    for (const char* c : kCpuMetrics) spec.metrics.push_back(std::string("cpu.") + c);
  // Only with one-shot approaches: their metrics (NEES first); with other filtered approaches
  // the NEES alone; files without a filter keep their spec.
  bool filtered = false;
  for (ncs::Approach a : s.approaches) filtered = filtered || ncs::filtered_approach(a);
  if (one_shot) {
    spec.metrics.insert(spec.metrics.end(), std::begin(kOneShotMetrics), std::end(kOneShotMetrics));
  } else if (filtered) {
    spec.metrics.insert(spec.metrics.end(), std::begin(kOneShotMetrics), std::begin(kOneShotMetrics) + kNeesMetricCount);
  }
  spec.config = loop_sweep_config(s);
  if (on_cpu) {  // likewise
    const ncs::ControllerCpu& c = *s.scenarios[0].controller_cpu;
    spec.config["controller_cpu"] = {{"cpu", c.set.name},
                                     {"job", c.set.tasks[c.task].name},
                                     {"scheduler", engine::cpu::to_string(c.set.scheduler)},
                                     {"utilization", c.set.utilization()},
                                     {"wcrt_us", static_cast<double>(c.wcrt.count()) * 1e-3},
                                     {"bcrt_us", static_cast<double>(c.bcrt.count()) * 1e-3}};
    spec.config["compute_us"] = "cpu";  // τ_c is the job's response on the CPU, not the U[min, max] draw
  }
  if (sensor_on_cpu) {  // likewise: shards of files with other sensor jobs do not merge
    const ncs::ControllerCpu& c = *s.scenarios[0].sensor_cpu;
    spec.config["sensor_cpu"] = {{"cpu", c.set.name},
                                 {"job", c.set.tasks[c.task].name},
                                 {"utilization", c.set.utilization()},
                                 {"sample_min_us", static_cast<double>(c.sample_min.count()) * 1e-3},
                                 {"sample_max_us", static_cast<double>(c.sample_max.count()) * 1e-3},
                                 {"wcrt_us", static_cast<double>(c.wcrt.count()) * 1e-3}};
  }
  if (one_shot && !s.scenarios.empty()) {  // the file's sensor rule and controller phase (the same in every scenario)
    const ncs::Scenario& x = s.scenarios[0];
    spec.config["one_shot"] = {{"send_on_delta", x.sod_delta}, {"time_steps", x.sod_time_steps},
                               {"controller_phase_us", x.controller_phase_us}};
    if (x.sensor_mtm) {  // only then: the spec of send-on-delta files stays as it was
      spec.config["one_shot"]["mtm"] = {{"sigma", x.mtm_sigma}, {"delta", x.mtm_delta}, {"k_max", x.mtm_k_max},
                                        {"k_ref_max", x.mtm_k_ref_max}};
    }
  }
  if (!board) spec.config["states"] = plant.a.rows;  // the NEES's n (only then: the board's spec stays as it was)
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
  const std::vector<std::string>* bus = &on_bus;
  ncs::ShapeCachePools pool;  // the sweep's, per plant shape: per thread, bounded (plant_cache_pool.hpp)
  ncs::RunOptions options;
  if (share_caches) options.caches = &pool;
  return engine::run_sweep(
      spec, shard, threads,
      [study, counter_maps, bus, analytic, on_cpu, one_shot, filtered, &options](std::size_t a, std::size_t k, std::uint64_t seed) {
        const ncs::Approach ap = study->approaches[a];
        const ncs::RunResult r = ncs::run(*study->ctx, ap, study->scenarios[k], seed, options);
        std::vector<double> v{r.cost, static_cast<double>(r.late), static_cast<double>(r.saturated),
                              static_cast<double>(r.faults)};
        for (std::size_t l = 0; l < study->links.size(); ++l) {
          const auto c = link_counts(r, (*counter_maps)[a][l], study->links[l]);
          v.insert(v.end(), c.begin(), c.end());
        }
        for (const std::string& l : *bus) {
          const auto d = bus_delays(r, l);
          v.insert(v.end(), d.begin(), d.end());
        }
        if (on_cpu) {
          const auto c = cpu_metrics(r);
          v.insert(v.end(), c.begin(), c.end());
        }
        if (one_shot) {
          v.insert(v.end(), {r.nees, static_cast<double>(r.nees_steps), static_cast<double>(r.sampled), static_cast<double>(r.sent)});
        } else if (filtered) {
          v.insert(v.end(), {r.nees, static_cast<double>(r.nees_steps)});
        }
        if (analytic) {  // ncs table --analytic's columns: the same run in analytic mode
          const auto x = ncs::analytic_metrics(*study->ctx, ap, study->scenarios[k], seed, options);
          v.insert(v.end(), x.begin(), x.end());
        }
        return v;
      },
      "study run");
}

}  // namespace oneshot::study
