/// @file study_check_text.cpp
/// @brief `study check`'s resolution as text, one fact per line (describe_resolution(), see
///        study_check.hpp).
#include "study_check.hpp"

#include <cstdio>
#include <sstream>
#include <string>

#include "study_cpu.hpp"
#include "study_one_shot_discretizer.hpp"

namespace oneshot::study {

using nlohmann::json;

std::string describe_resolution(const json& r) {
  std::ostringstream o;
  o << "study file " << r.at("source").get<std::string>() << " (study " << r.at("study").get<std::string>() << ")\n";
  const auto plant_line = [&o](const json& p) {
    o << "plant: " << p.at("kind").get<std::string>() << ", n = " << p.at("n") << ", m = " << p.at("m") << ", p = " << p.at("p");
    if (p.contains("name")) o << " (" << p.at("name").get<std::string>() << ", h = " << p.at("period_us") << " us)";
    if (p.contains("runs_on_shape")) {
      const json& s = p.at("runs_on_shape");
      o << "; the ncs loops run it on the shape (" << s.at("n") << ", " << s.at("m") << ", " << s.at("p") << ")"
        << (s.at("padded").get<bool>() ? ", zero padded" : ", its own");
    }
    o << "\n";
    if (p.contains("continuous_equivalent")) {
      const json& e = p.at("continuous_equivalent");
      o << "  runs as its exact continuous equivalent (ZOH inverse): A = " << e.at("A").dump() << ", B = " << e.at("B").dump()
        << ", Q_c = " << e.at("Q_c").dump() << "; sampled back at h: relative error " << e.at("reconstruction_relative_error")
        << " (Phi, Gamma), " << e.at("noise_relative_error") << " (Q)\n";
      if (e.contains("warning")) o << "  warning: " << e.at("warning").get<std::string>() << "\n";
    }
  };
  const auto approach_lines = [&o](const json& list, const char* indent) {
  for (const json& a : list) {
    o << indent << "approach " << a.at("name").get<std::string>() << " (" << a.at("kind").get<std::string>()
      << "): " << a.at("design").get<std::string>();
    if (a.contains("lqr_gain")) o << "; L = " << a.at("lqr_gain").dump() << ", closed-loop radius " << a.at("closed_loop_spectral_radius");
    if (a.contains("kalman_gain")) o << "; K = " << a.at("kalman_gain").dump() << ", estimator radius " << a.at("estimator_spectral_radius");
    o << "\n";
    if (a.contains("discretizer")) o << indent << "  " << describe_discretizer(a.at("discretizer")) << "\n";
    if (a.contains("per_scenario"))
      for (const auto& [sc, g] : a.at("per_scenario").items()) o << "  " << sc << ": " << g.dump() << "\n";
  }
  };
  if (r.contains("loops")) {  // several loops: each with its plant and designs
    for (const json& l : r.at("loops")) {
      o << "loop " << l.at("name").get<std::string>() << ": sensor " << l.at("sensor").get<std::string>() << ", controller "
        << l.at("controller").get<std::string>() << ", actuator " << l.at("actuator").get<std::string>();
      if (l.contains("clock_offset_us")) o << "; phase " << l.at("clock_offset_us").dump() << " us (its timer at kh + phase)";
      o << "\n  ";
      plant_line(l.at("plant"));
      approach_lines(l.at("approaches"), "  ");
    }
  } else {
    plant_line(r.at("plant"));
    approach_lines(r.at("approaches"), "");
  }
  for (const json& l : r.at("links")) {
    o << "link " << l.at("name").get<std::string>() << " " << l.at("from").get<std::string>() << " -> "
      << l.at("to").get<std::string>();
    if (l.contains("bus")) {
      o << ": CAN bus " << l.at("bus").get<std::string>() << ", id " << l.at("id") << "\n";
      continue;
    }
    const json& b = l.at("base");
    const auto line = [&](const json& x) {
      char buf[160];
      const json& d = x.at("delay");
      std::snprintf(buf, sizeof buf, "delay min %.1f / mean %.1f / max %s us, loss %.4g, %s", d.at("min_us").get<double>(),
                    d.at("mean_us").get<double>(), d.at("max_us").is_null() ? "unbounded" : d.at("max_us").dump().c_str(),
                    x.at("loss_probability").get<double>(), x.at("order").get<std::string>().c_str());
      return std::string(buf);
    };
    o << ": " << line(b) << "\n";
    if (l.contains("scenarios"))
      for (const auto& [sc, x] : l.at("scenarios").items()) o << "  scenario " << sc << ": " << line(x) << "\n";
  }
  if (r.contains("buses")) {
    for (const json& b : r.at("buses")) {
      o << "bus " << b.at("name").get<std::string>() << ": load " << 100 * b.at("load").get<double>() << " %\n";
      const auto messages = [&o](const json& list, const std::string& indent) {
        for (const json& m : list) {
          o << indent << m.at("kind").get<std::string>() << " " << m.at("name").get<std::string>() << " id " << m.at("id")
            << ": C " << m.at("transmission_us") << " us, jitter "
            << (m.at("jitter_us").is_null() ? std::string("unbounded") : m.at("jitter_us").dump() + " us") << ", worst response "
            << (m.at("worst_response_us").is_null() ? std::string("unbounded") : m.at("worst_response_us").dump() + " us") << "\n";
        }
      };
      messages(b.at("messages"), "  ");
      if (b.contains("scenarios")) {
        for (const auto& [sc, list] : b.at("scenarios").items()) {
          o << "  scenario " << sc << ":\n";
          messages(list, "    ");
        }
      }
    }
  }
  if (r.contains("cpus")) o << describe_cpus(r.at("cpus"));
  o << "grid: " << r.at("grid").at("approaches") << " approaches x " << r.at("grid").at("scenarios") << " scenarios x "
    << r.at("seeds").at("count") << " seeds = " << r.at("grid").at("runs") << " runs\n";
  return o.str();
}

}  // namespace oneshot::study
