/// @file study_loops_sweep.cpp
/// @brief The sweep and summary of a study file with several loops on one engine (see
///        study_ncs_sweep.hpp: run_loops_sweep(), loop_results(), loops_outputs()).
#include <cmath>
#include <iterator>
#include <string>
#include <utility>
#include <vector>

#include "ncs_cache_pools.hpp"
#include "ncs_loop.hpp"
#include "oneshot/util/number_text.hpp"
#include "oneshot/util/statistics.hpp"
#include "study_ncs_sweep.hpp"

namespace oneshot::study {

using util::format_f;
namespace {

/// Observed delays of one leg over a set of runs.
struct LegDelays {
  double messages = 0;  ///< Messages over every run.
  double sum_us = 0;    ///< Σ delays.
  double min_us = 0;    ///< Smallest (valid when messages > 0).
  double max_us = 0;    ///< Largest.

  /// Adds one run's metrics (messages, min, max, sum).
  void add(double n, double lo, double hi, double sum) {
    if (n <= 0) return;
    min_us = messages == 0 ? lo : std::fmin(min_us, lo);
    max_us = std::fmax(max_us, hi);
    messages += n;
    sum_us += sum;
  }

  /// As JSON: messages, min_us, mean_us, max_us (null without messages).
  nlohmann::json json() const {
    const auto or_null = [this](double v) { return messages > 0 ? nlohmann::json(v) : nlohmann::json(nullptr); };
    return {{"messages", messages}, {"min_us", or_null(min_us)}, {"mean_us", or_null(messages > 0 ? sum_us / messages : 0)},
            {"max_us", or_null(max_us)}};
  }
};

/// Leg delays of metric prefix `p` ("<loop>/<leg>." or "<loop>/alone.<leg>.") over every run of approach `a`.
LegDelays leg_delays(const engine::SweepResults& r, std::size_t a, const std::string& p) {
  const std::size_t mm = r.metric(p + "bus_messages"), mn = r.metric(p + "bus_delay_min_us"), mx = r.metric(p + "bus_delay_max_us"),
                    ms = r.metric(p + "bus_delay_sum_us");
  LegDelays d;
  for (std::size_t s = 0; s < r.spec.scenarios.size(); ++s)
    for (std::size_t k = 0; k < r.spec.seeds; ++k) d.add(r.at(a, s, k, mm), r.at(a, s, k, mn), r.at(a, s, k, mx), r.at(a, s, k, ms));
  return d;
}

}  // namespace

engine::SweepResults run_loops_sweep(const NcsStudy& s, std::size_t seeds, unsigned threads, const engine::Shard& shard,
                                     bool analytic, bool share_caches) {
  if (analytic) throw engine::InputError("field '--analytic': no analytic cost for a file with several loops (loops[])");
  engine::SweepSpec spec = study_sweep_spec(s, seeds, "run");
  bool filtered = false;  // SK or IK: each loop's NEES
  for (ncs::Approach a : s.approaches) filtered = filtered || ncs::filtered_approach(a);
  spec.config = {{"study_file", s.source}, {"loops", nlohmann::json::array()}};
  for (const NcsStudy& l : s.loops) {
    nlohmann::json c = loop_sweep_config(l);
    c["name"] = l.loop;
    c["addresses"] = l.addresses;
    c["file_links"] = l.link_names;
    if (l.clock_offset_us != 0) c["clock_offset_us"] = l.clock_offset_us;  // only then: the spec of files without stays as it was
    spec.config["loops"].push_back(c);
    for (const std::string& m : loop_sweep_metrics(l)) spec.metrics.push_back(l.loop + "/" + m);
    if (filtered)  // as a file of one loop: the filter's NEES (only then: files without SK, IK keep their spec)
      for (std::size_t m = 0; m < kNeesMetricCount; ++m) spec.metrics.push_back(l.loop + "/" + kOneShotMetrics[m]);
  }
  std::vector<std::vector<std::string>> bus_legs;  // per loop its legs on a CAN bus (the same in every run)
  for (const NcsStudy& l : s.loops) {
    bus_legs.push_back(bus_links(l));
    spec.metrics.push_back(l.loop + "/alone.cost");
    for (const std::string& leg : bus_legs.back())
      for (const char* c : kBusDelayMetrics) spec.metrics.push_back(l.loop + "/alone." + leg + "." + c);
  }
  const NcsStudy* study = &s;
  const std::vector<std::vector<std::string>>* legs_on_bus = &bus_legs;
  ncs::ShapeCachePools pool;  // the sweep's, per plant shape: per thread, bounded (plant_cache_pool.hpp)
  ncs::ShapeCachePools* caches = share_caches ? &pool : nullptr;
  return engine::run_sweep(
      spec, shard, threads,
      [study, legs_on_bus, filtered, caches](std::size_t a, std::size_t k, std::uint64_t seed) {
        const ncs::Approach ap = study->approaches[a];
        const std::vector<ncs::LoopOnBus> loops = loops_on_bus(*study, k);
        const std::vector<ncs::RunResult> shared = ncs::run_loops(loops, ap, seed, caches);
        std::vector<double> v;
        for (std::size_t i = 0; i < loops.size(); ++i) {
          const std::vector<double> x = loop_sweep_values(study->loops[i], a, shared[i], (*legs_on_bus)[i]);
          v.insert(v.end(), x.begin(), x.end());
          if (filtered) v.insert(v.end(), {shared[i].nees, static_cast<double>(shared[i].nees_steps)});
        }
        for (std::size_t i = 0; i < loops.size(); ++i) {  // the loop alone on the engine: the same seed and streams
          const ncs::RunResult alone = ncs::run_loops({loops[i]}, ap, seed, caches)[0];
          v.push_back(alone.cost);
          for (const std::string& leg : (*legs_on_bus)[i]) {
            double d[std::size(kBusDelayMetrics)] = {};
            for (const auto& [nm, st] : alone.bus_legs) {
              if (nm != leg) continue;
              d[0] = static_cast<double>(st.delivered);
              d[1] = static_cast<double>(st.min_delay.count()) * 1e-3;
              d[2] = static_cast<double>(st.max_delay.count()) * 1e-3;
              d[3] = static_cast<double>(st.total_delay.count()) * 1e-3;
            }
            v.insert(v.end(), std::begin(d), std::end(d));
          }
        }
        return v;
      },
      "study run");
}

std::vector<ncs::LoopOnBus> loops_on_bus(const NcsStudy& s, std::size_t scenario) {
  std::vector<ncs::LoopOnBus> loops;
  for (const NcsStudy& l : s.loops) {
    loops.push_back({l.ctx.get(), &l.scenarios.at(scenario), l.loop, l.addresses[0], l.addresses[1], l.addresses[2],
                     l.clock_offset_us});
  }
  return loops;
}

engine::SweepResults loop_results(const engine::SweepResults& results, std::size_t i) {
  const nlohmann::json& c = results.spec.config.at("loops").at(i);
  const std::string prefix = c.at("name").get<std::string>() + "/";
  engine::SweepResults out;
  out.spec = results.spec;
  out.spec.config = c;
  out.spec.config.erase("name");
  out.spec.config.erase("addresses");
  out.spec.config.erase("file_links");
  out.spec.metrics.clear();
  std::vector<std::size_t> pick;
  for (std::size_t m = 0; m < results.spec.metrics.size(); ++m) {
    const std::string& nm = results.spec.metrics[m];
    if (nm.rfind(prefix, 0) != 0 || nm.rfind(prefix + "alone.", 0) == 0) continue;
    out.spec.metrics.push_back(nm.substr(prefix.size()));
    pick.push_back(m);
  }
  out.shard = results.shard;
  out.done = results.done;
  const std::size_t runs = results.spec.runs();
  out.values.reserve(runs * pick.size());
  for (std::size_t r = 0; r < runs; ++r)
    for (std::size_t m : pick) out.values.push_back(results.at(r, m));
  return out;
}

nlohmann::json loops_outputs(const engine::SweepResults& results, const std::string& out_dir, bool plots) {
  const engine::SweepSpec& spec = results.spec;
  nlohmann::json j = {{"experiment", "study run"}, {"study_file", spec.config.at("study_file")}, {"seeds", spec.seeds},
                      {"first_seed", spec.first_seed}};
  std::string md, order, interference;
  const nlohmann::json& loops = spec.config.at("loops");
  for (std::size_t i = 0; i < loops.size(); ++i) {
    const std::string name = loops[i].at("name").get<std::string>();
    const nlohmann::json one = run_outputs(loop_results(results, i), out_dir + "/" + name, plots);
    j["loops"][name] = one;
    md += "\n### Loop " + name + " (plant " + loops[i].at("plant").get<std::string>() + ")\n" + one.at("markdown").get<std::string>();
    order += (order.empty() ? "" : "; ") + name + ": " + one.at("order_text").get<std::string>();
    // The paired comparison: the loop on the shared bus against alone on it, per seed.
    const std::size_t shared_m = results.metric(name + "/cost"), alone_m = results.metric(name + "/alone.cost");
    std::string cost_md = "\n| loop " + name + " | J shared | J alone | shared - alone | ratio shared / alone |\n|---|---:|---:|---:|---:|\n";
    std::string delay_md = "\n| loop " + name + " | leg | messages | alone min / mean / max (us) | shared min / mean / max (us) | "
                           "worst-case response (us) | within |\n|---|---|---:|---|---|---:|---|\n";
    for (std::size_t a = 0; a < spec.approaches.size(); ++a) {
      std::vector<double> shared_k, alone_k, diff_k, ratio_k;
      for (std::size_t k = 0; k < spec.seeds; ++k) {
        double sh = 0, al = 0;
        for (std::size_t s = 0; s < spec.scenarios.size(); ++s) {
          sh += results.at(a, s, k, shared_m);
          al += results.at(a, s, k, alone_m);
        }
        const double n = static_cast<double>(spec.scenarios.size());
        shared_k.push_back(sh / n);
        alone_k.push_back(al / n);
        diff_k.push_back((sh - al) / n);
        ratio_k.push_back(al > 0 ? sh / al : 1.0);
      }
      const util::Summary sh = util::summarize(shared_k), al = util::summarize(alone_k), df = util::summarize(diff_k),
                          rt = util::summarize(ratio_k);
      nlohmann::json e = {{"cost_shared_mean", sh.mean}, {"cost_shared_ci95", sh.ci95}, {"cost_alone_mean", al.mean},
                          {"cost_alone_ci95", al.ci95}, {"shared_minus_alone_mean", df.mean},
                          {"shared_minus_alone_ci95", df.ci95}, {"ratio_shared_to_alone_mean", rt.mean},
                          {"ratio_shared_to_alone_ci95", rt.ci95}};
      cost_md += "| " + spec.approaches[a] + " | " + format_f(sh.mean, 6) + " ± " + format_f(sh.ci95, 6) + " | " + format_f(al.mean, 6) + " ± " +
                 format_f(al.ci95, 6) + " | " + format_f(df.mean, 6, true) + " ± " + format_f(df.ci95, 6) + " | " + format_f(rt.mean, 4) +
                 " ± " + format_f(rt.ci95, 4) + " |\n";
      if (loops[i].contains("bus_links")) {
        for (const auto& l : loops[i].at("bus_links")) {
          const std::string leg = l.get<std::string>();
          const LegDelays sd = leg_delays(results, a, name + "/" + leg + ".");
          const LegDelays ad = leg_delays(results, a, name + "/alone." + leg + ".");
          const nlohmann::json& w = one.at("bus_delays").at(spec.approaches[a]).at(leg).at("worst_response_us");
          const bool within = sd.messages == 0 || (!w.is_null() && sd.max_us <= w.get<double>());
          e["bus_delays"][leg] = {{"shared", sd.json()}, {"alone", ad.json()}, {"worst_response_us", w}, {"within_bound", within}};
          if (sd.messages == 0) continue;  // I and IK: nothing on the bus
          delay_md += "| " + spec.approaches[a] + " | " + leg + " | " + format_f(sd.messages, 0) + " | " + format_f(ad.min_us, 1) +
                      " / " + format_f(ad.sum_us / ad.messages, 1) + " / " + format_f(ad.max_us, 1) + " | " +
                      format_f(sd.min_us, 1) + " / " + format_f(sd.sum_us / sd.messages, 1) + " / " + format_f(sd.max_us, 1) +
                      " | " + (w.is_null() ? std::string("unbounded") : w.dump()) + " | " + (within ? "yes" : "no") + " |\n";
        }
      }
      j["interference"][name][spec.approaches[a]] = e;
    }
    std::string x = "\nLoop " + name + " with the other loops on the bus (shared) and alone on it, the same seeds (per seed the "
                    "mean over the scenarios; 95 % intervals over the seeds):\n" + cost_md;
    if (loops[i].contains("bus_links")) x += delay_md;
    md += x;
    interference += x;
  }
  j["markdown"] = md;
  j["markdown_interference"] = interference;
  j["order_text"] = order;
  return j;
}

}  // namespace oneshot::study
