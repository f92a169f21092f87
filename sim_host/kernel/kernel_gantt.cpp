/// @file kernel_gantt.cpp
/// @brief The Gantt chart of the first hyperperiod, from the CPU's event log.
#include "kernel_gantt.hpp"

#include <algorithm>
#include <numeric>
#include <sstream>

#include "oneshot/util/output_files.hpp"

namespace oneshot::sim {

using namespace engine::cpu;

engine::Duration first_hyperperiod(const TaskSet& set) {
  std::int64_t lcm_us = 1, offset_us = 0;
  const std::int64_t cap_us = 1'000'000;
  for (const auto* l : {&set.tasks, &set.isrs}) {
    for (const TaskSpec& t : *l) {
      offset_us = std::max(offset_us, t.offset.count() / 1000);
      if (!t.sporadic && lcm_us <= cap_us) lcm_us = std::lcm(lcm_us, t.period.count() / 1000);
    }
  }
  return engine::from_us(std::min(cap_us, offset_us + std::min(lcm_us, cap_us)));
}

nlohmann::json write_gantt(const Cpu& cpu, engine::Duration span, const std::string& dir, bool plots) {
  struct Segment {
    std::size_t row;
    double from_ms, to_ms;
  };
  std::vector<Segment> segs;
  std::vector<double> since(cpu.entities(), -1);
  const double end_ms = static_cast<double>(span.count()) * 1e-6;
  for (const CpuLogEntry& e : cpu.log()) {
    const double t = static_cast<double>(e.t_ns) * 1e-6;
    if (t > end_ms) break;
    double& s = since[e.entity];
    if (e.kind == CpuEventKind::kStart || e.kind == CpuEventKind::kResume) {
      s = t;
    } else if ((e.kind == CpuEventKind::kPreempt || e.kind == CpuEventKind::kFinish || e.kind == CpuEventKind::kAbort) && s >= 0) {
      if (t > s) segs.push_back(Segment{e.entity, s, t});
      s = -1;
    }
  }
  for (std::size_t r = 0; r < since.size(); ++r) {
    if (since[r] >= 0 && end_ms > since[r]) segs.push_back(Segment{r, since[r], end_ms});
  }
  std::vector<std::vector<double>> rows;
  for (const Segment& s : segs) rows.push_back({static_cast<double>(s.row), s.from_ms, s.to_ms});
  util::make_directory(dir);
  util::write_csv(dir + "/gantt.csv", {"row", "start_ms", "end_ms"}, rows);
  nlohmann::json j = {{"span_us", static_cast<double>(span.count()) * 1e-3}, {"segments", segs.size()},
                      {"files", {"gantt.csv"}}};
  if (plots) {
    std::ostringstream g;
    g << util::gnuplot_png_terminal(1200, static_cast<int>(160 + 40 * cpu.entities()), 10)
      << "set output 'gantt.png'\nset datafile separator ','\nset xlabel 'time (ms)'\nset grid xtics\n"
      << "set yrange [-0.7:" << static_cast<double>(cpu.entities()) - 0.3 << "]\nset xrange [0:" << end_ms << "]\n"
      << "set title " << util::gnuplot_quote("first hyperperiod (at most 1 s): " + std::to_string(span.count() / 1000) + " us") << "\nset ytics (";
    for (std::size_t r = 0; r < cpu.entities(); ++r) g << (r ? ", " : "") << util::gnuplot_quote(cpu.entity_name(r)) << " " << r;
    g << ")\nset style fill solid 0.8\nunset key\n"
      << "plot 'gantt.csv' skip 1 using (($2+$3)/2):1:(($3-$2)/2):(0.35):1 with boxxyerror lc variable\n";
    util::run_gnuplot(dir, "gantt.gp", g.str());
    j["files"].push_back("gantt.png");
  }
  return j;
}

}  // namespace oneshot::sim
