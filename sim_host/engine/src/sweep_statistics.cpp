/// @file sweep_statistics.cpp
/// @brief Sweep summaries (see sweep_statistics.hpp).
#include "oneshot/engine/sweep_statistics.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>

#include "oneshot/util/output_files.hpp"

namespace oneshot::engine {
namespace {

nlohmann::json number_or_null(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); }

}  // namespace

SweepSummary summarize_metric(const SweepResults& r, std::size_t metric, std::size_t reference) {
  if (!r.complete()) throw std::logic_error("sweep " + r.spec.experiment + ": summary of an incomplete sweep");
  const std::size_t na = r.spec.approaches.size();
  const std::size_t ns = r.spec.scenarios.size();
  const std::size_t nk = r.spec.seeds;
  if (reference >= na) throw std::invalid_argument("sweep: reference approach out of range");
  SweepSummary out;
  out.metric = metric;
  out.reference = reference;
  out.per_seed.assign(na, std::vector<double>(nk, 0));
  for (std::size_t a = 0; a < na; ++a)
    for (std::size_t k = 0; k < nk; ++k)
      for (std::size_t s = 0; s < ns; ++s) out.per_seed[a][k] += r.at(a, s, k, metric) / static_cast<double>(ns);
  for (std::size_t s = 0; s < ns; ++s)
    for (std::size_t k = 0; k < nk; ++k) out.reference_has_zero = out.reference_has_zero || r.at(reference, s, k, metric) == 0;
  const double ref_mean = util::summarize(out.per_seed[reference]).mean;
  for (std::size_t a = 0; a < na; ++a) {
    out.value.push_back(util::summarize(out.per_seed[a]));
    out.ratio_of_means.push_back(out.value[a].mean / ref_mean);
    std::vector<double> ratios(nk);
    for (std::size_t k = 0; k < nk; ++k) ratios[k] = out.per_seed[a][k] / out.per_seed[reference][k];
    out.ratio.push_back(util::summarize(ratios));
    std::vector<double> weighted(nk, 0);
    for (std::size_t k = 0; k < nk; ++k)
      for (std::size_t s = 0; s < ns; ++s)
        weighted[k] += r.at(a, s, k, metric) / r.at(reference, s, k, metric) / static_cast<double>(ns);
    out.ratio_weighted.push_back(util::summarize(weighted));
    std::vector<Summary> per;
    std::vector<Summary> per_ratio;
    for (std::size_t s = 0; s < ns; ++s) {
      std::vector<double> v(nk);
      std::vector<double> q(nk);
      for (std::size_t k = 0; k < nk; ++k) {
        v[k] = r.at(a, s, k, metric);
        q[k] = v[k] / r.at(reference, s, k, metric);
      }
      per.push_back(util::summarize(v));
      per_ratio.push_back(util::summarize(q));
    }
    out.per_scenario.push_back(per);
    out.per_scenario_ratio.push_back(per_ratio);
  }
  for (std::size_t a = 0; a < na; ++a)
    for (std::size_t b = a + 1; b < na; ++b) {
      std::vector<double> d(nk);
      for (std::size_t k = 0; k < nk; ++k) d[k] = out.per_seed[a][k] - out.per_seed[b][k];
      out.paired.push_back({a, b, util::summarize(d)});
    }
  return out;
}

nlohmann::json summary_json(const SweepResults& r, const SweepSummary& sm) {
  nlohmann::json j;
  j["metric"] = r.spec.metrics[sm.metric];
  j["reference"] = r.spec.approaches[sm.reference];
  j["seeds"] = r.spec.seeds;
  for (std::size_t a = 0; a < r.spec.approaches.size(); ++a) {
    j["approaches"][r.spec.approaches[a]] = {{"mean", sm.value[a].mean},
                                              {"ci95", sm.value[a].ci95},
                                              {"ratio_to_reference", number_or_null(sm.ratio_of_means[a])},
                                              {"ratio_mean", number_or_null(sm.ratio[a].mean)},
                                              {"ratio_ci95", number_or_null(sm.ratio[a].ci95)},
                                              {"ratio_scenario_weighted", number_or_null(sm.ratio_weighted[a].mean)},
                                              {"ratio_scenario_weighted_ci95", number_or_null(sm.ratio_weighted[a].ci95)}};
  }
  nlohmann::json per = nlohmann::json::array();
  for (std::size_t s = 0; s < r.spec.scenarios.size(); ++s) {
    nlohmann::json e = {{"name", r.spec.scenarios[s]}};
    for (std::size_t a = 0; a < r.spec.approaches.size(); ++a) {
      e["approaches"][r.spec.approaches[a]] = {{"mean", sm.per_scenario[a][s].mean},
                                                {"ci95", sm.per_scenario[a][s].ci95},
                                                {"ratio_mean", number_or_null(sm.per_scenario_ratio[a][s].mean)},
                                                {"ratio_ci95", number_or_null(sm.per_scenario_ratio[a][s].ci95)}};
    }
    per.push_back(e);
  }
  j["per_scenario"] = per;
  j["paired_differences"] = paired_differences_json(r, sm);
  return j;
}

nlohmann::json paired_differences_json(const SweepResults& r, const SweepSummary& sm) {
  nlohmann::json j = nlohmann::json::object();
  for (const auto& p : sm.paired) {
    j[r.spec.approaches[p.a] + "-" + r.spec.approaches[p.b]] = {{"mean", number_or_null(p.diff.mean)},
                                                                {"ci95", number_or_null(p.diff.ci95)}};
  }
  return j;
}

void add_order_by_mean(nlohmann::json& j, const SweepResults& r, const SweepSummary& sm) {
  std::vector<std::pair<double, std::string>> order;
  for (std::size_t a = 0; a < r.spec.approaches.size(); ++a) order.emplace_back(sm.value[a].mean, r.spec.approaches[a]);
  // Finite means first by (mean, name), then the non-finite ones (a diverged approach: inf or
  // NaN) by name: a NaN inside std::pair's order would break the strict weak order the sort needs.
  std::stable_sort(order.begin(), order.end(), [](const auto& x, const auto& y) {
    const bool fx = std::isfinite(x.first);
    const bool fy = std::isfinite(y.first);
    if (fx != fy) return fx;
    if (fx && x.first != y.first) return x.first < y.first;
    return x.second < y.second;
  });
  std::string text;
  for (const auto& o : order) {
    j["order_by_mean_cost"].push_back(o.second);
    text += (text.empty() ? "" : " < ") + o.second;
  }
  j["order_text"] = text;
}

void write_runs_csv(const SweepResults& r, const std::string& path, util::NonFinite non_finite) {
  std::vector<std::string> header = {"approach_index", "scenario_index", "seed"};
  header.insert(header.end(), r.spec.metrics.begin(), r.spec.metrics.end());
  std::vector<std::vector<double>> rows;
  for (std::size_t a = 0; a < r.spec.approaches.size(); ++a)
    for (std::size_t s = 0; s < r.spec.scenarios.size(); ++s)
      for (std::size_t k = 0; k < r.spec.seeds; ++k) {
        std::vector<double> row = {static_cast<double>(a), static_cast<double>(s),
                                   static_cast<double>(r.spec.first_seed + k)};
        for (std::size_t m = 0; m < r.spec.metrics.size(); ++m) row.push_back(r.at(a, s, k, m));
        rows.push_back(row);
      }
  util::write_csv(path, header, rows, non_finite);
}

void write_summary_files(const SweepResults& r, const SweepSummary& sm, const std::string& dir, const std::string& prefix,
                         bool plots) {
  const auto in = [&](const std::string& name) { return (std::filesystem::path(dir) / name).string(); };
  write_runs_csv(r, in(prefix + "_runs.csv"));
  std::vector<std::vector<double>> rows;
  for (std::size_t a = 0; a < r.spec.approaches.size(); ++a) {
    rows.push_back({static_cast<double>(a), sm.value[a].mean, sm.value[a].ci95, sm.ratio[a].mean, sm.ratio[a].ci95});
  }
  util::write_csv(in(prefix + "_summary.csv"), {"approach_index", "mean", "ci95", "ratio_mean", "ratio_ci95"}, rows);
  if (!plots) return;
  // Names may come from a study or shard file: every label reaches gnuplot as a quoted
  // string constant (util::gnuplot_quote), never as script text.
  std::ostringstream tics;
  for (std::size_t a = 0; a < r.spec.approaches.size(); ++a) {
    tics << (a ? ", " : "") << util::gnuplot_quote(r.spec.approaches[a]) << " " << a;
  }
  std::ostringstream g;
  g << util::gnuplot_png_terminal(1100, 700) << "set output " << util::gnuplot_quote(prefix + ".png") << "\n"
    << "set datafile separator ','\nset grid ytics\nset style fill solid 0.6\nset boxwidth 0.6\nset key off\n"
    << "set xtics (" << tics.str() << ")\nset xrange [-0.6:" << static_cast<double>(r.spec.approaches.size()) - 0.4 << "]\nset yrange [0:*]\n"
    << "set ylabel "
    << util::gnuplot_quote(r.spec.metrics[sm.metric] + " (mean over scenarios, 95 % CI over " + std::to_string(r.spec.seeds) +
                          " seeds)")
    << "\nplot " << util::gnuplot_quote(prefix + "_summary.csv") << " using 1:2 skip 1 with boxes lc rgb '#4c72b0', '' using 1:2:3 skip 1 with "
    << "yerrorbars pt 0 lw 2 lc rgb 'black'\n";
  util::run_gnuplot(dir, prefix + ".gp", g.str());
}

}  // namespace oneshot::engine
