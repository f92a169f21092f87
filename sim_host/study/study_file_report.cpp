/// @file study_file_report.cpp
/// @brief The markdown of `oneshot-sim study report` (see study_file_report.hpp).
#include "study_file_report.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <sstream>
#include <vector>

#include "ncs_experiments.hpp"
#include "ncs_loop.hpp"
#include "oneshot/util/output_files.hpp"
#include "study_ncs_runner.hpp"
#include "study_ncs_sweep.hpp"

namespace oneshot::study {

std::string report_markdown(const std::string& file, const std::string& resolution_text,
                            const std::string& simulated_time_text, const engine::SweepResults& results,
                            const nlohmann::json& outputs, const std::string& plot_path) {
  const engine::SweepSpec& spec = results.spec;
  std::vector<std::string> pairs;  // every pair, in the file's order of approaches
  for (std::size_t a = 0; a < spec.approaches.size(); ++a)
    for (std::size_t b = a + 1; b < spec.approaches.size(); ++b) pairs.push_back(spec.approaches[a] + "-" + spec.approaches[b]);
  std::ostringstream md;
  md << "## Study file `" << std::filesystem::path(file).filename().string() << "`\n\n"
     << "`oneshot-sim study report " << file << "`: " << spec.approaches.size() << " approaches x " << spec.scenarios.size()
     << " scenarios x " << spec.seeds << " seeds (first seed " << spec.first_seed
     << "), the same delay and noise draws for every approach (common random numbers).\n\n"
     << "### Configuration\n\nAs `oneshot-sim study check` resolves it:\n\n```text\n" << resolution_text << "```\n\n"
     << simulated_time_text << "\n\n"
     << "### Cost\n\n" << ncs::table_section_markdown(outputs, pairs, plot_path)
     << "Per scenario (mean cost of " << spec.approaches[0] << ", ratio of each approach's mean cost to " << spec.approaches[0]
     << "'s):\n\n"
     << outputs.at("markdown_per_scenario").get<std::string>() << "\n### Links\n\n"
     << "Totals over every run: sent (handed to the link), delivered (not lost), lost (dropped by the loss model), "
        "late (dropped by the receiver as stale: not newer than what it holds, or after its period; the periods without a "
        "command are the late column of the cost table), refused (by the receiver's frame checks).\n\n"
     << "| approach | link |";
  for (const char* c : kLinkCounters) md << " " << c << " |";
  md << "\n|---|---|";
  for (std::size_t i = 0; i < std::size(kLinkCounters); ++i) md << "---|";
  md << "\n";
  const nlohmann::json& links = outputs.at("links");
  for (const std::string& a : spec.approaches) {
    for (const auto& l : spec.config.at("links")) {
      const nlohmann::json& e = links.at(a).at(l.get<std::string>());
      md << "| " << a << " | " << l.get<std::string>() << " |";
      for (const char* c : kLinkCounters) {
        char v[32];
        std::snprintf(v, sizeof v, " %.0f |", e.at(c).get<double>());
        md << v;
      }
      md << "\n";
    }
  }
  if (outputs.contains("markdown_cpu")) {
    const nlohmann::json& c = spec.config.at("controller_cpu");
    md << "\n### Controller CPU\n\nThe controller's job `" << c.at("job").get<std::string>() << "` on CPU `"
       << c.at("cpu").get<std::string>() << "` (" << c.at("scheduler").get<std::string>()
       << "): its response time tau_c over every run, beside the analysis's BCRT and WCRT; misses of the job and of the "
          "CPU's other tasks and ISRs; the CPU's busy time over the simulated time. I and IK do not use the CPU.\n"
       << outputs.at("markdown_cpu").get<std::string>();
  }
  return md.str();
}

}  // namespace oneshot::study

namespace oneshot::study {
namespace {

/// An approach's name in file names ('+' is not welcome in every tool).
std::string file_stem(const std::string& approach) {
  std::string out;
  for (char c : approach) out += c == '+' ? std::string("plus") : std::string(1, c);
  return "trace_" + out;
}

/// The gnuplot script of one approach's trace (see write_traces()).
std::string trace_plot(const std::string& stem, const std::string& title, bool estimates, const std::vector<std::string>& legs,
                       double duration_s, double window_s) {
  std::ostringstream g;
  g << util::gnuplot_png_terminal(1100, 950, 10) << "set output '" << stem << ".png'\n"
    << "set datafile separator ','\nset grid\nset key outside right\nset lmargin 10\nset rmargin 22\nset multiplot layout 3,1 title '" << title << "'\n"
    << "set xrange [0:" << duration_s << "]\nset ylabel 'state (V)'\n"
    << "plot '" << stem << "_states.csv' using 1:2 skip 1 with lines lw 1.2 lc rgb '#000000' title 'x1', '' using 1:3 skip 1 "
    << "with lines lw 1.2 lc rgb '#4c72b0' title 'x2', '' using 1:4 skip 1 with lines dt 2 lc rgb 'gray' title 'r1'";
  if (estimates) {
    g << ", '" << stem << "_estimates.csv' using 1:2 skip 1 with points pt 2 ps 0.4 lc rgb '#c44e52' title 'xhat1', '' using 1:3 "
      << "skip 1 with points pt 2 ps 0.4 lc rgb '#55a868' title 'xhat2'";
  }
  g << "\nset ylabel 'u (V)'\nplot '" << stem << "_states.csv' using 1:5 skip 1 with steps lc rgb '#000000' title 'u applied'\n"
    << "set xrange [0:" << window_s << "]\nset xlabel 't (s), first " << window_s << " s'\nset ylabel 'leg'\nset yrange [0.3:"
    << static_cast<double>(legs.size()) + 0.7 << "]\nset ytics (";
  for (std::size_t i = 0; i < legs.size(); ++i) g << (i == 0 ? "" : ", ") << "'" << legs[i] << "' " << legs.size() - i;
  g << ")\nplot '" << stem << "_messages.csv' using ($6>0 ? $3 : 1/0):($2+0.3):($6>0 ? $4-$3 : 1/0):(-0.3) skip 1 with vectors head "
    << "filled size screen 0.006,20 lc rgb '#4c72b0' title 'sent -> arrived', '' using 3:($5>0 ? $2+0.3 : 1/0) skip 1 with "
    << "points pt 2 ps 1.2 lw 2 lc rgb '#c44e52' title 'lost'\nunset multiplot\n";
  return g.str();
}

}  // namespace

std::vector<std::size_t> trace_selection(const std::vector<std::string>& approaches, const std::string& source,
                                         const std::string& names) {
  std::vector<std::size_t> out;
  if (names.empty()) {
    for (std::size_t a = 0; a < approaches.size() && a < kMaxDefaultTraces; ++a) out.push_back(a);
    return out;
  }
  std::string known;
  for (const std::string& a : approaches) known += (known.empty() ? "" : ", ") + a;
  std::istringstream in(names);
  std::string n;
  while (std::getline(in, n, ',')) {
    std::size_t a = 0;
    while (a < approaches.size() && n != approaches[a]) ++a;
    if (a == approaches.size()) {
      throw engine::InputError("field '--trace': no approach '" + n + "' in " + source + " (its approaches: " + known + ")");
    }
    if (std::find(out.begin(), out.end(), a) != out.end()) throw engine::InputError("field '--trace': approach '" + n + "' given twice");
    out.push_back(a);
  }
  if (out.empty() || names.back() == ',') throw engine::InputError("field '--trace': an empty approach name");
  return out;
}

std::vector<std::size_t> trace_selection(const NcsStudy& s, const std::string& names) {
  std::vector<std::string> approaches;
  for (ncs::Approach a : s.approaches) approaches.emplace_back(ncs::name(a));
  return trace_selection(approaches, s.source, names);
}

nlohmann::json write_traces(const NcsStudy& s, const std::vector<std::size_t>& selected, const std::string& out_dir, bool plots) {
  nlohmann::json j = nlohmann::json::object();
  if (s.scenarios.empty()) return j;
  const ncs::Scenario& sc = s.scenarios[0];
  ncs::RunOptions ro;
  // Every millisecond, at most 5000 rows (longer runs: a coarser step in whole ms).
  ro.trace_step_s = std::max(1.0, std::ceil(sc.duration_s / 5.0)) * 1e-3;
  ro.record_messages = true;
  const double h_s = s.ctx->period_us() * 1e-6;
  const double window_s = std::min(sc.duration_s, 30 * h_s);
  for (std::size_t a : selected) {
    const ncs::Approach ap = s.approaches[a];
    const std::string an = ncs::name(ap);
    const std::string stem = file_stem(an);
    // With clock offsets the loop at phase 0: its own time, the same cost to the bit (ncs::at_phase_zero()).
    const ncs::RunResult r = ncs::run(*s.ctx, ap, ncs::at_phase_zero(sc, ap), s.first_seed, ro);
    std::vector<std::vector<double>> rows;
    rows.reserve(r.truth.size());
    for (std::size_t i = 0; i < r.truth.size() && i < r.setpoint.size(); ++i) {
      rows.push_back({r.truth[i].t_s, r.truth[i].v[0], r.truth[i].v[1], r.setpoint[i].v[0], r.setpoint[i].v[1]});
    }
    util::write_csv(util::path_in(out_dir, stem + "_states.csv"), {"t_s", "x1", "x2", "r1", "u"}, rows);
    nlohmann::json e = {{"scenario", sc.name}, {"seed", s.first_seed}, {"cost", r.cost}, {"trace_step_s", ro.trace_step_s},
                        {"files", {stem + "_states.csv"}}};
    if (!r.estimates.empty()) {
      rows.clear();
      for (const ncs::Point& p : r.estimates)
        if (p.t_s <= sc.duration_s) rows.push_back({p.t_s, p.v[0], p.v[1]});
      util::write_csv(util::path_in(out_dir, stem + "_estimates.csv"), {"t_s", "xhat1", "xhat2"}, rows);
      e["files"].push_back(stem + "_estimates.csv");
    }
    // The legs the run built, in the file's order (I and IK have no leg as).
    std::vector<std::string> legs;
    for (const std::string& l : s.links)
      for (const auto& [nm, st] : r.links)
        if (nm == l) legs.push_back(l);
    std::ostringstream m;
    m << "leg,leg_index,sent_s,arrival_s,lost,delivered\n";
    char buf[96];
    nlohmann::json counts = nlohmann::json::object();
    for (const std::string& l : legs) counts[l] = {{"sent", 0}, {"delivered", 0}, {"lost", 0}};
    for (const ncs::MessageEvent& x : r.messages) {
      const auto it = std::find(legs.begin(), legs.end(), x.leg);
      if (it == legs.end()) continue;
      const std::size_t y = legs.size() - static_cast<std::size_t>(it - legs.begin());
      if (x.delivered) {
        std::snprintf(buf, sizeof buf, ",%zu,%.9f,%.9f,%d,1\n", y, x.sent_s, x.arrival_s, x.lost ? 1 : 0);
      } else {
        std::snprintf(buf, sizeof buf, ",%zu,%.9f,,%d,0\n", y, x.sent_s, x.lost ? 1 : 0);
      }
      m << x.leg << buf;
      nlohmann::json& c = counts[x.leg];
      c["sent"] = c["sent"].get<int>() + 1;
      if (x.lost) c["lost"] = c["lost"].get<int>() + 1;
      else c["delivered"] = c["delivered"].get<int>() + 1;
    }
    util::write_text(util::path_in(out_dir, stem + "_messages.csv"), m.str());
    e["files"].push_back(stem + "_messages.csv");
    e["messages"] = counts;
    e["timeline_s"] = window_s;
    if (plots) {
      char title[256];
      std::snprintf(title, sizeof title, "%s on %s, seed %llu: states, input, messages", an.c_str(), sc.name.c_str(),
                    static_cast<unsigned long long>(s.first_seed));
      util::run_gnuplot(out_dir, stem + ".gp", trace_plot(stem, title, !r.estimates.empty(), legs, sc.duration_s, window_s));
      e["files"].push_back(stem + ".png");
    }
    j[an] = e;
  }
  return j;
}

std::string traces_markdown(const nlohmann::json& traces, const engine::SweepResults& results, bool plots) {
  std::ostringstream md;
  if (traces.empty()) return "";
  const std::size_t cost = results.metric("cost");
  md << "\n### Traces\n\nOne run per approach on the first scenario and the first seed (the sweep's run: same seed, same "
        "draws; the trace only observes). "
     << (plots ? "Each plot: the true states x1, x2 with the set-point r1 and the controller's estimates (crosses: the "
                 "actuation-synchronized and one-shot loops record them); the applied input u; a time line of the first "
                 "30 periods with one arrow per delivered message of each leg from its sending to its arrival and a red "
                 "cross per lost one."
               : "CSV files only (--no-plots).")
     << "\n\n";
  for (std::size_t a = 0; a < results.spec.approaches.size(); ++a) {  // in the file's order
    const std::string& an = results.spec.approaches[a];
    if (!traces.contains(an)) continue;
    const nlohmann::json& e = traces.at(an);
    char line[160];
    std::snprintf(line, sizeof line, "cost %.6g (the sweep's run: %.6g)", e.at("cost").get<double>(),
                  results.at(a, 0, 0, cost));
    md << "- " << an << " on " << e.at("scenario").get<std::string>() << ": " << line << "; files:";
    for (const auto& f : e.at("files")) md << " [" << f.get<std::string>() << "](" << f.get<std::string>() << ")";
    md << "\n";
    for (const auto& f : e.at("files")) {
      const std::string n = f.get<std::string>();
      if (n.size() > 4 && n.compare(n.size() - 4, 4, ".png") == 0) md << "\n  ![" << an << " trace](" << n << ")\n\n";
    }
  }
  return md.str();
}

void mark_same_cost_as_sweep(nlohmann::json& traces, const engine::SweepResults& r, const std::vector<std::size_t>& traced) {
  const std::size_t cost = r.metric("cost");
  for (std::size_t a : traced) {  // the traced run is the sweep's: the same cost, bit for bit
    const std::string& an = r.spec.approaches[a];
    if (!traces.contains(an)) continue;
    const nlohmann::json& traced_cost = traces[an].at("cost");
    const double swept = r.at(a, 0, 0, cost);
    traces[an]["same_cost_as_sweep"] = traced_cost.is_null() ? !std::isfinite(swept) : traced_cost.get<double>() == swept;
  }
}

}  // namespace oneshot::study
