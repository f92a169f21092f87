/// @file study_ncs_summary.cpp
/// @brief The summary of `oneshot-sim study run` (see study_ncs_sweep.hpp run_outputs()): ncs
///        table's keys plus the per-link counters, the CAN bus delays, the controller's CPU,
///        the filters' NEES and the one-shot sensors' send rates.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "ncs_experiments.hpp"
#include "ncs_model.hpp"
#include "oneshot/util/statistics.hpp"
#include "study_ncs_sweep.hpp"

namespace oneshot::study {

namespace {

/// Adds "bus_delays" (per approach, per leg on a bus: observed delays over every run beside
/// the analysis's worst-case response time) and its table to the markdown.
void add_bus_delays(nlohmann::json& j, const engine::SweepResults& results) {
  const engine::SweepSpec& spec = results.spec;
  std::string md = "\n| approach | leg | messages | min delay (us) | mean delay (us) | max delay (us) | worst-case response (us) |\n"
                   "|---|---|---:|---:|---:|---:|---:|\n";
  for (std::size_t a = 0; a < spec.approaches.size(); ++a) {
    for (const auto& l : spec.config.at("bus_links")) {
      const std::string leg = l.get<std::string>();
      const std::size_t mm = results.metric(leg + ".bus_messages");
      const std::size_t mn = results.metric(leg + ".bus_delay_min_us");
      const std::size_t mx = results.metric(leg + ".bus_delay_max_us");
      const std::size_t ms = results.metric(leg + ".bus_delay_sum_us");
      nlohmann::json e = nlohmann::json::object();
      double n_all = 0, sum_all = 0, min_all = 0, max_all = 0;
      nlohmann::json wcrt_all = 0.0;
      for (std::size_t s = 0; s < spec.scenarios.size(); ++s) {
        double n = 0, sum = 0, lo = 0, hi = 0;
        for (std::size_t k = 0; k < spec.seeds; ++k) {
          const double c = results.at(a, s, k, mm);
          if (c <= 0) continue;
          lo = n == 0 ? results.at(a, s, k, mn) : std::fmin(lo, results.at(a, s, k, mn));
          hi = std::fmax(hi, results.at(a, s, k, mx));
          n += c;
          sum += results.at(a, s, k, ms);
        }
        const nlohmann::json& w = spec.config.at("scenarios")[s].at("bus_legs").at(leg).at("worst_response_us");
        if (w.is_null() || wcrt_all.is_null()) {
          wcrt_all = nullptr;
        } else {
          wcrt_all = std::fmax(wcrt_all.get<double>(), w.get<double>());
        }
        nlohmann::json x = {{"messages", n}, {"worst_response_us", w}};
        x["min_us"] = n > 0 ? nlohmann::json(lo) : nlohmann::json(nullptr);
        x["mean_us"] = n > 0 ? nlohmann::json(sum / n) : nlohmann::json(nullptr);
        x["max_us"] = n > 0 ? nlohmann::json(hi) : nlohmann::json(nullptr);
        e["per_scenario"][spec.scenarios[s]] = x;
        if (n > 0) {
          min_all = n_all == 0 ? lo : std::fmin(min_all, lo);
          max_all = std::fmax(max_all, hi);
          n_all += n;
          sum_all += sum;
        }
      }
      e["messages"] = n_all;
      e["min_us"] = n_all > 0 ? nlohmann::json(min_all) : nlohmann::json(nullptr);
      e["mean_us"] = n_all > 0 ? nlohmann::json(sum_all / n_all) : nlohmann::json(nullptr);
      e["max_us"] = n_all > 0 ? nlohmann::json(max_all) : nlohmann::json(nullptr);
      e["worst_response_us"] = wcrt_all;
      e["within_bound"] = n_all == 0 || (!wcrt_all.is_null() && max_all <= wcrt_all.get<double>());
      j["bus_delays"][spec.approaches[a]][leg] = e;
      if (n_all == 0) continue;  // I and IK: delay-free links, nothing on the bus
      char row[256];
      std::snprintf(row, sizeof row, "| %s | %s | %.0f | %.3f | %.3f | %.3f | %s |\n", spec.approaches[a].c_str(), leg.c_str(), n_all,
                    min_all, sum_all / n_all, max_all, wcrt_all.is_null() ? "unbounded" : wcrt_all.dump().c_str());
      md += row;
    }
  }
  j["markdown"] = j.at("markdown").get<std::string>() + md;
}

/// Adds "cpu" (per approach: the controller job's observed response times over every run
/// beside the analysis's bounds, misses, measured utilization) and its table to the markdown.
void add_cpu_stats(nlohmann::json& j, const engine::SweepResults& results) {
  const engine::SweepSpec& spec = results.spec;
  const nlohmann::json& cfg = spec.config.at("controller_cpu");
  const double wcrt = cfg.at("wcrt_us").get<double>(), bcrt = cfg.at("bcrt_us").get<double>();
  std::size_t m[std::size(kCpuMetrics)];
  for (std::size_t i = 0; i < std::size(kCpuMetrics); ++i) m[i] = results.metric(std::string("cpu.") + kCpuMetrics[i]);
  std::string md = "\n| approach | controller jobs | min tau_c (us) | mean tau_c (us) | max tau_c (us) | BCRT (us) | WCRT (us) | "
                   "within | deadline misses | other misses | utilization |\n|---|---:|---:|---:|---:|---:|---:|---|---:|---:|---:|\n";
  for (std::size_t a = 0; a < spec.approaches.size(); ++a) {
    double n = 0, lo = 0, hi = 0, sum = 0, miss = 0, other = 0, busy = 0, time_us = 0;
    for (std::size_t s = 0; s < spec.scenarios.size(); ++s) {
      const double dur_us = spec.config.at("scenarios")[s].at("duration_s").get<double>() * 1e6;
      for (std::size_t k = 0; k < spec.seeds; ++k) {
        const double c = results.at(a, s, k, m[0]);
        time_us += dur_us;
        busy += results.at(a, s, k, m[6]);
        other += results.at(a, s, k, m[5]);
        if (c <= 0) continue;
        lo = n == 0 ? results.at(a, s, k, m[1]) : std::fmin(lo, results.at(a, s, k, m[1]));
        hi = std::fmax(hi, results.at(a, s, k, m[2]));
        n += c;
        sum += results.at(a, s, k, m[3]);
        miss += results.at(a, s, k, m[4]);
      }
    }
    nlohmann::json e = {{"jobs", n}, {"wcrt_us", wcrt}, {"bcrt_us", bcrt}, {"deadline_misses", miss}, {"other_misses", other},
                        {"utilization_measured", time_us > 0 ? busy / time_us : 0.0}};
    e["min_us"] = n > 0 ? nlohmann::json(lo) : nlohmann::json(nullptr);
    e["mean_us"] = n > 0 ? nlohmann::json(sum / n) : nlohmann::json(nullptr);
    e["max_us"] = n > 0 ? nlohmann::json(hi) : nlohmann::json(nullptr);
    e["within_bounds"] = n == 0 || (lo >= bcrt && hi <= wcrt);
    j["cpu"][spec.approaches[a]] = e;
    if (n == 0) continue;  // I and IK: delay-free, not on the CPU
    char row[320];
    std::snprintf(row, sizeof row, "| %s | %.0f | %.1f | %.1f | %.1f | %.1f | %.1f | %s | %.0f | %.0f | %.4f |\n", spec.approaches[a].c_str(), n,
                  lo, sum / n, hi, bcrt, wcrt, e.at("within_bounds").get<bool>() ? "yes" : "no", miss, other,
                  e.at("utilization_measured").get<double>());
    md += row;
  }
  j["markdown"] = j.at("markdown").get<std::string>() + md;
  j["markdown_cpu"] = md;
}

/// The NEES of approach index `a` (a filtered approach): {"nees_mean", "nees_ci95"} over seeds
/// of the per-seed mean over the scenarios with a NEES (a run without a regular P, e.g. noise
/// scale 0, has none: left out, never counted as 0), "steps" the computations averaged, and per
/// scenario {"nees_mean", "nees_ci95"} over seeds.
nlohmann::json nees_of(const engine::SweepResults& results, std::size_t a) {
  const engine::SweepSpec& spec = results.spec;
  const std::size_t nees_i = results.metric("nees");
  const std::size_t steps_i = results.metric("nees_steps");
  const auto summary = [](const std::vector<double>& v) {
    if (v.empty()) return nlohmann::json::array({nullptr, nullptr});
    const util::Summary m = util::summarize(v);
    return nlohmann::json::array({m.mean, m.ci95});
  };
  std::vector<double> per_seed;
  double steps = 0;
  for (std::size_t k = 0; k < spec.seeds; ++k) {
    double sum = 0;
    std::size_t count = 0;
    for (std::size_t x = 0; x < spec.scenarios.size(); ++x) {
      steps += results.at(a, x, k, steps_i);
      if (results.at(a, x, k, steps_i) > 0) {
        sum += results.at(a, x, k, nees_i);
        ++count;
      }
    }
    if (count > 0) per_seed.push_back(sum / static_cast<double>(count));
  }
  const nlohmann::json overall = summary(per_seed);
  nlohmann::json e = {{"nees_mean", overall[0]}, {"nees_ci95", overall[1]}, {"steps", steps}};
  for (std::size_t x = 0; x < spec.scenarios.size(); ++x) {
    std::vector<double> nees;
    for (std::size_t k = 0; k < spec.seeds; ++k)
      if (results.at(a, x, k, steps_i) > 0) nees.push_back(results.at(a, x, k, nees_i));
    const nlohmann::json m = summary(nees);
    e["per_scenario"][spec.scenarios[x]] = {{"nees_mean", m[0]}, {"nees_ci95", m[1]}};
  }
  return e;
}

/// Adds "one_shot" (per one-shot approach: the filter's NEES as nees_of(), and the sensor's
/// send rate, overall and per scenario) and the send rates' table to the markdown (the NEES is
/// in add_nees()'s table).
void add_one_shot(nlohmann::json& j, const engine::SweepResults& results) {
  const engine::SweepSpec& spec = results.spec;
  const std::size_t sampled = results.metric("sensor.samples");
  const std::size_t sent = results.metric("sensor.sent");
  std::string md = "\n| approach | samples sent |\n|---|---:|\n";
  for (std::size_t a = 0; a < spec.approaches.size(); ++a) {
    if (!ncs::one_shot(ncs::parse_any_approach(spec.approaches[a]))) continue;
    nlohmann::json e = nees_of(results, a);
    e.erase("steps");
    double n_all = 0, s_all = 0;
    for (std::size_t x = 0; x < spec.scenarios.size(); ++x) {
      double n = 0, sn = 0;
      for (std::size_t k = 0; k < spec.seeds; ++k) {
        n += results.at(a, x, k, sampled);
        sn += results.at(a, x, k, sent);
      }
      nlohmann::json& p = e["per_scenario"][spec.scenarios[x]];
      p["samples"] = n;
      p["sent"] = sn;
      p["send_rate"] = n > 0 ? sn / n : 0.0;
      n_all += n;
      s_all += sn;
    }
    e["samples"] = n_all;
    e["sent"] = s_all;
    e["send_rate"] = n_all > 0 ? s_all / n_all : 0.0;
    j["one_shot"][spec.approaches[a]] = e;
    char row[120];
    std::snprintf(row, sizeof row, "| %s | %.4f |\n", spec.approaches[a].c_str(), e["send_rate"].get<double>());
    md += row;
  }
  j["markdown"] = j.at("markdown").get<std::string>() + md;
}

/// Adds "nees" (per approach whose controller runs a Kalman filter: nees_of()) and its table to
/// the markdown.
void add_nees(nlohmann::json& j, const engine::SweepResults& results) {
  const engine::SweepSpec& spec = results.spec;
  const std::size_t n = spec.config.contains("states") ? spec.config.at("states").get<std::size_t>() : ncs::kN;
  std::string md = "\n| approach | NEES (n = " + std::to_string(n) + ") | 95 % CI | filter steps |\n|---|---:|---:|---:|\n";
  for (std::size_t a = 0; a < spec.approaches.size(); ++a) {
    if (!ncs::filtered_approach(ncs::parse_any_approach(spec.approaches[a]))) continue;
    const nlohmann::json e = nees_of(results, a);
    j["nees"][spec.approaches[a]] = e;
    const double steps = e.at("steps").get<double>();
    char row[200];
    if (e.at("nees_mean").is_null()) {
      std::snprintf(row, sizeof row, "| %s | — | — | %.0f |\n", spec.approaches[a].c_str(), steps);
    } else {
      std::snprintf(row, sizeof row, "| %s | %.4f | ± %.4f | %.0f |\n", spec.approaches[a].c_str(),
                    e.at("nees_mean").get<double>(), e.at("nees_ci95").get<double>(), steps);
    }
    md += row;
  }
  j["markdown"] = j.at("markdown").get<std::string>() + md;
}

}  // namespace

nlohmann::json run_outputs(const engine::SweepResults& results, const std::string& out_dir, bool plots) {
  if (results.spec.config.contains("loops")) return loops_outputs(results, out_dir, plots);  // study_loops_sweep.cpp
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
  if (spec.config.contains("bus_links")) add_bus_delays(j, results);
  if (spec.config.contains("controller_cpu")) add_cpu_stats(j, results);
  if (std::find(spec.metrics.begin(), spec.metrics.end(), "nees") != spec.metrics.end()) add_nees(j, results);
  if (std::find(spec.metrics.begin(), spec.metrics.end(), "sensor.samples") != spec.metrics.end()) add_one_shot(j, results);
  return j;
}

}  // namespace oneshot::study
