/// @file study_check.cpp
/// @brief A study file resolved into its designs, link summaries and CAN bounds (see
///        study_check.hpp).
#include "study_check.hpp"

#include <cmath>
#include <algorithm>
#include <cstdio>
#include <iterator>
#include <map>
#include <optional>
#include <sstream>

#include "ncs_model.hpp"
#include "oneshot/design/controller_synthesis.hpp"
#include "oneshot/design/plant_description.hpp"
#include "oneshot/engine/can_analysis.hpp"
#include "oneshot/node/message.hpp"
#include "study_ncs_runner.hpp"

namespace oneshot::study {
namespace {

using engine::InputError;
using nlohmann::json;

json rows(const design::DenseMatrix& m) {
  json out = json::array();
  for (std::size_t i = 0; i < m.rows; ++i) {
    json r = json::array();
    for (std::size_t j = 0; j < m.cols; ++j) r.push_back(m(i, j));
    out.push_back(r);
  }
  return out;
}

double us(engine::Duration d) { return static_cast<double>(d.count()) * 1e-3; }

json delay_summary(const engine::DelayModel& d) {
  json j = {{"model", d.describe()}, {"min_us", us(d.lower_bound())}, {"mean_us", d.mean_ns() * 1e-3}};
  const auto ub = d.upper_bound();
  if (ub) {
    j["max_us"] = us(*ub);
  } else {
    j["max_us"] = nullptr;
    // Only the heavy tails are capped (draws above the cap are clamped); Poisson is not.
    if (d.kind == engine::DelayModel::Kind::kLognormal || d.kind == engine::DelayModel::Kind::kPareto) j["cap_us"] = us(d.cap);
  }
  return j;
}

json link_summary(const engine::LinkConfig& c) {
  return {{"delay", delay_summary(c.delay)},
          {"loss", c.loss.describe()},
          {"loss_probability", c.loss.loss_rate()},
          {"order", c.fifo ? "fifo" : "any"}};
}

bool has_estimator(const std::string& kind) {
  return kind == "AK" || kind == "AKx" || kind == "AKl" || kind == "SK" || kind == "IK";
}

bool ncs_kind(const std::string& kind) {
  for (ncs::Approach a : ncs::kAllApproaches)
    if (kind == ncs::name(a)) return true;
  return false;
}

/// The smallest timer period of the file (0 when no node runs a timer).
engine::Duration loop_period(const engine::StudyFile& f) {
  engine::Duration p{0};
  for (const engine::NodeSpec& n : f.nodes)
    if (n.mode == "timer" && (p.count() == 0 || n.period < p)) p = n.period;
  return p;
}

/// When a node sends, after the release of the timer that starts its chain: [lo, hi].
struct SendWindow {
  engine::Duration lo{0};  ///< Earliest.
  engine::Duration hi{0};  ///< Latest.
  bool operator==(const SendWindow& o) const { return lo == o.lo && hi == o.hi; }
};

/// Bytes of the loop message a link carries on a CAN bus: for study ncs the loop's own
/// (network.hpp sends it in frames of ≤ 8 bytes): sc the sampling loops' report (header +
/// p doubles; the actuation-synchronized loops, whose report is longer, do not run on a
/// bus), ca a command (header + m doubles), as a request (header + m doubles); otherwise
/// kLoopFramePayloadBytes (one frame).
std::size_t loop_message_bytes(const engine::StudyFile& f, const std::string& link) {
  if (f.study != "ncs") return kLoopFramePayloadBytes;
  if (link == "sc") return node::encoded_size<double, ncs::kP>();
  if (link == "ca" || link == "as") return node::encoded_size<double, ncs::kM>();
  return kLoopFramePayloadBytes;
}

/// Delay of each loop message on a CAN bus, by link name: [C, R] (its transmission, its worst
/// response), from the bus analysis; a link on a bus without an entry is unbounded.
using BusDelays = std::map<std::string, SendWindow>;

/// The send window of `node` under scenario `s` (nullptr: the file's links): a timer node
/// [0, 0]; an arrival node the union over its incoming links of the sender's window plus the
/// link's delay bounds (a link on a CAN bus: [C, R] of its message from `bus`), plus the
/// computation on arrival τ_c of study ncs (U[1, 5] ms, the only computation time study files
/// model); with no incoming link [0, 0]. nullopt when unbounded: a delay model with no upper
/// bound, a bus message without a bound, a cycle of arrival nodes.
std::optional<SendWindow> send_window(const engine::StudyFile& f, const std::string& node, const engine::ScenarioSpec* s,
                                      const BusDelays& bus, std::size_t depth = 0) {
  if (f.node(node).mode != "arrival") return SendWindow{};
  if (depth > f.nodes.size()) return std::nullopt;
  std::optional<SendWindow> w;
  for (const engine::LinkSpec& l : f.links) {
    if (l.to != node) continue;
    const std::optional<SendWindow> up = send_window(f, l.from, s, bus, depth + 1);
    if (!up) return std::nullopt;
    SendWindow x;
    if (!l.bus.empty()) {
      const auto it = bus.find(l.name);
      if (it == bus.end()) return std::nullopt;
      x = SendWindow{up->lo + it->second.lo, up->hi + it->second.hi};
    } else {
      const engine::DelayModel d = f.link_config(l.name, s).delay;
      const std::optional<engine::Duration> ub = d.upper_bound();
      if (!ub) return std::nullopt;
      x = SendWindow{up->lo + d.lower_bound(), up->hi + *ub};
    }
    w = w ? SendWindow{std::min(w->lo, x.lo), std::max(w->hi, x.hi)} : x;
  }
  if (!w) return SendWindow{};
  const ncs::Timing t;
  return SendWindow{w->lo + engine::from_us(t.compute_min_us), w->hi + engine::from_us(t.compute_max_us)};
}

/// Release jitter of the loop messages among `links` (the bus's streams from index
/// `first_link`) under scenario `s`: its sender's send window hi − lo; nullopt when unbounded.
std::vector<std::optional<engine::Duration>> loop_jitters(const engine::StudyFile& f, const std::vector<const engine::LinkSpec*>& links,
                                                          const engine::ScenarioSpec* s, const BusDelays& bus) {
  std::vector<std::optional<engine::Duration>> out;
  for (const engine::LinkSpec* l : links) {
    const std::optional<SendWindow> w = send_window(f, l->from, s, bus);
    out.push_back(w ? std::optional<engine::Duration>(w->hi - w->lo) : std::nullopt);
  }
  return out;
}

/// The response-time analysis of a bus's streams, the loop messages (from index `first_link`)
/// with the release jitters `jitters`: one with an unbounded jitter is analyzed with 0 and
/// reported unbounded, with every stream of lower priority (its interference on them has no
/// bound).
json bus_messages(std::vector<engine::CanStream> streams, const std::vector<std::string>& kinds, std::size_t first_link,
                  const std::vector<std::optional<engine::Duration>>& jitters, const engine::CanBusConfig& config) {
  std::vector<bool> unbounded_jitter(streams.size(), false);
  for (std::size_t k = 0; k < jitters.size(); ++k) {
    streams[first_link + k].jitter = jitters[k].value_or(engine::Duration{0});
    unbounded_jitter[first_link + k] = !jitters[k];
  }
  const std::vector<engine::CanStreamBound> bounds = engine::can_response_times(streams, config);
  json out = json::array();
  for (std::size_t k = 0; k < streams.size(); ++k) {
    bool bounded = bounds[k].bounded;
    for (std::size_t i = 0; i < streams.size(); ++i)
      if (unbounded_jitter[i] && streams[i].id <= streams[k].id) bounded = false;
    json m = {{"name", streams[k].name}, {"kind", kinds[k]}, {"id", streams[k].id},
              {"payload_bytes", streams[k].payload_bytes}, {"frames", streams[k].leading_frames + 1},
              {"message_bytes", 8 * streams[k].leading_frames + streams[k].payload_bytes}, {"period_us", us(streams[k].period)},
              {"jitter_us", unbounded_jitter[k] ? json(nullptr) : json(us(streams[k].jitter))},
              {"deadline_us", us(streams[k].deadline)}, {"transmission_us", us(bounds[k].transmission)},
              {"bounded", bounded}, {"schedulable", bounded && bounds[k].schedulable}};
    m["worst_response_us"] = bounded ? json(us(bounds[k].response)) : json(nullptr);
    out.push_back(m);
  }
  return out;
}

json plant_section(const engine::StudyFile& f, json& designs) {
  json j;
  switch (f.plant.kind) {
    case engine::PlantSpec::Kind::kContinuous:
      j = {{"kind", "continuous"}, {"n", f.plant.continuous.a.rows}, {"m", f.plant.continuous.b.cols},
           {"p", f.plant.continuous.c.rows}, {"designed", false},
           {"why_not_designed", "an inline plant carries no measurement covariance: give a plant file"}};
      return j;
    case engine::PlantSpec::Kind::kDiscrete:
      j = {{"kind", "discrete"}, {"n", f.plant.discrete.phi.rows}, {"m", f.plant.discrete.gamma.cols},
           {"p", f.plant.discrete.c.rows}, {"period_us", us(f.plant.discrete.period)}, {"designed", false},
           {"why_not_designed", "an inline plant carries no measurement covariance: give a plant file"}};
      return j;
    case engine::PlantSpec::Kind::kFile:
      break;
  }
  const std::string path = plant_file_path(f);
  design::PlantDescription p;
  try {
    p = design::load_plant_file(path);
  } catch (const std::exception& e) {
    throw InputError("field 'plant.file': " + std::string(e.what()));
  }
  design::DesignResult d;
  try {
    d = design::synthesize(p);
  } catch (const std::exception& e) {
    throw InputError("field 'plant': " + std::string(e.what()));
  }
  if (!d.lqr_available) throw InputError("field 'plant': no LQR gain: " + d.lqr_unavailable_reason);
  j = {{"kind", "file"}, {"file", path}, {"name", p.name}, {"form", design::to_string(p.form)},
       {"n", p.n()}, {"m", p.m()}, {"p", p.p()}, {"period_us", p.period_us}, {"designed", true}};
  designs["lqr_gain"] = rows(d.l);
  designs["closed_loop_spectral_radius"] = d.closed_loop_radius;
  designs["kalman_gain"] = rows(d.kalman_gain);
  designs["estimator_spectral_radius"] = d.estimator_radius;
  return j;
}

}  // namespace

json resolve_study(const engine::StudyFile& f) {
  try {
    json r;
    r["source"] = f.source;
    r["study"] = f.study;
    r["duration_s"] = f.duration_s;
    r["seeds"] = {{"first", f.first_seed}, {"count", f.seeds}};
    json design = json::object();
    r["plant"] = plant_section(f, design);
    const bool designed = r["plant"].at("designed").get<bool>();
    // Per approach: the design its kind implies.
    std::shared_ptr<const ncs::Context> ctx;
    for (const engine::ApproachSpec& a : f.approaches) {
      json e = {{"name", a.name}, {"kind", a.kind}, {"params", a.params}};
      if (!designed) {
        e["design"] = "none (plant not designed)";
      } else if (f.study != "ncs" || !ncs_kind(a.kind)) {
        e["design"] = "LQR (the kind is not an ncs approach: no estimator assumed)";
        e["lqr_gain"] = design["lqr_gain"];
        e["closed_loop_spectral_radius"] = design["closed_loop_spectral_radius"];
      } else {
        e["lqr_gain"] = design["lqr_gain"];
        e["closed_loop_spectral_radius"] = design["closed_loop_spectral_radius"];
        e["design"] = has_estimator(a.kind) ? "LQR + Kalman" : "LQR";
        if (has_estimator(a.kind)) {
          e["kalman_gain"] = design["kalman_gain"];
          e["estimator_spectral_radius"] = design["estimator_spectral_radius"];
        }
        if (a.kind == "S+") {  // its own gain per scenario (add_ncs_designs)
          e["design"] = "LQR on eq. 8 at the mean delay tau_io of each scenario";
          e.erase("lqr_gain");
          e.erase("closed_loop_spectral_radius");
        }
      }
      r["approaches"].push_back(e);
    }
    // Links: point to point per scenario; bus messages by the CAN analysis.
    const engine::Duration period = loop_period(f);
    for (const engine::LinkSpec& l : f.links) {
      json e = {{"name", l.name}, {"from", l.from}, {"to", l.to}};
      if (l.bus.empty()) {
        e["base"] = link_summary(f.link_config(l.name));
        for (const engine::ScenarioSpec& s : f.scenarios) {
          if (s.delays.count(l.name) != 0 || s.losses.count(l.name) != 0) {
            e["scenarios"][s.name] = link_summary(f.link_config(l.name, &s));
          }
        }
      } else {
        e["bus"] = l.bus;
        e["id"] = l.id;
      }
      r["links"].push_back(e);
    }
    // Buses: the streams of each, then their analysis together (a loop message's jitter may
    // come from a message on a bus before it in its chain: iterated to a fixed point).
    struct Bus {
      std::vector<engine::CanStream> streams;
      std::vector<std::string> kinds;
      std::size_t first_link = 0;
      std::vector<const engine::LinkSpec*> on_bus;
      std::vector<engine::Duration> message_time;  ///< C of each loop message (every frame).
    };
    std::vector<Bus> buses;
    for (std::size_t b = 0; b < f.buses.size(); ++b) {
      const engine::BusSpec& bus = f.buses[b];
      const std::string field = "buses[" + std::to_string(b) + "]";
      Bus x;
      x.streams = bus.background;
      x.kinds.assign(x.streams.size(), "background");
      x.first_link = x.streams.size();
      const engine::Duration bit{1'000'000'000 / bus.config.bit_rate};
      for (const engine::LinkSpec& l : f.links) {
        if (l.bus != bus.config.name) continue;
        const engine::NodeSpec& from = f.node(l.from);
        const engine::Duration t = from.mode == "timer" ? from.period : period;
        if (t.count() <= 0) throw InputError("field '" + field + "': link " + l.name + " has no period (no timer node)");
        const std::size_t bytes = loop_message_bytes(f, l.name);
        engine::CanStream st;
        st.name = l.name;
        st.id = l.id;
        st.leading_frames = (bytes - 1) / 8;
        st.payload_bytes = bytes - 8 * st.leading_frames;
        st.period = t;
        st.deadline = t;
        x.streams.push_back(st);
        x.kinds.emplace_back("link");
        x.on_bus.push_back(&l);
        x.message_time.push_back(bit * (static_cast<std::int64_t>(st.leading_frames) * engine::can_frame_bits(8, bus.config.extended_ids) +
                                        engine::can_frame_bits(st.payload_bytes, bus.config.extended_ids)));
      }
      double load = 0;
      for (const engine::CanStream& st : x.streams) {
        const std::int64_t bits = static_cast<std::int64_t>(st.leading_frames) * engine::can_frame_bits(8, bus.config.extended_ids) +
                                  engine::can_frame_bits(st.payload_bytes, bus.config.extended_ids);
        load += static_cast<double>((bit * bits).count()) / static_cast<double>(st.period.count());
      }
      if (load > 1) {
        char buf[64];
        std::snprintf(buf, sizeof buf, "%.1f", 100 * load);
        throw InputError("field '" + field + "': bus " + bus.config.name + " is loaded " + buf + " % (over 100 %)");
      }
      r["buses"].push_back({{"name", bus.config.name}, {"bit_rate", bus.config.bit_rate}, {"load", load}});
      buses.push_back(std::move(x));
    }
    // Every bus under scenario `s`: from every loop message at its transmission time, the
    // jitters and responses until the delays [C, R] stop moving (they only grow); after 64
    // rounds a message still moving is taken unbounded.
    const auto analyze = [&](const engine::ScenarioSpec* s) {
      BusDelays delays;
      for (const Bus& x : buses)
        for (std::size_t k = 0; k < x.on_bus.size(); ++k) delays[x.on_bus[k]->name] = SendWindow{x.message_time[k], x.message_time[k]};
      std::vector<json> out(buses.size());
      for (std::size_t round = 0;; ++round) {
        BusDelays next;
        for (std::size_t b = 0; b < buses.size(); ++b) {
          const Bus& x = buses[b];
          out[b] = bus_messages(x.streams, x.kinds, x.first_link, loop_jitters(f, x.on_bus, s, delays), f.buses[b].config);
          for (std::size_t k = 0; k < x.on_bus.size(); ++k) {
            const json& m = out[b][x.first_link + k];
            if (m.at("worst_response_us").is_null()) continue;
            const engine::Duration resp{std::llround(m.at("worst_response_us").get<double>() * 1e3)};
            next[x.on_bus[k]->name] = SendWindow{x.message_time[k], resp};
          }
        }
        if (next == delays) break;
        if (round >= 64) {
          for (auto it = next.begin(); it != next.end();) {
            const auto old = delays.find(it->first);
            it = old == delays.end() || !(old->second == it->second) ? next.erase(it) : std::next(it);
          }
        }
        delays = next;
      }
      return out;
    };
    const std::vector<json> base = analyze(nullptr);
    for (std::size_t b = 0; b < buses.size(); ++b) r["buses"][b]["messages"] = base[b];
    // A scenario whose link overrides change a loop message's jitter: its own analysis.
    for (const engine::ScenarioSpec& s : f.scenarios) {
      const std::vector<json> own = analyze(&s);
      for (std::size_t b = 0; b < buses.size(); ++b)
        if (own[b] != base[b]) r["buses"][b]["scenarios"][s.name] = own[b];
    }
    // The grid.
    for (const engine::ScenarioSpec& s : f.scenarios) {
      r["scenarios"].push_back({{"name", s.name}, {"duration_s", s.duration_s.value_or(f.duration_s)}, {"params", s.params}});
    }
    r["grid"] = {{"approaches", f.approaches.size()}, {"scenarios", f.scenarios.size()},
                 {"runs_per_seed", f.approaches.size() * f.scenarios.size()},
                 {"runs", f.approaches.size() * f.scenarios.size() * f.seeds}};
    return r;
  } catch (const InputError& e) {
    throw InputError(f.source + ": " + e.what());
  }
}

void add_ncs_designs(json& r, const NcsStudy& s) {
  for (auto& a : r["approaches"]) {
    if (a.at("kind") != "S+") continue;
    for (const ncs::Scenario& sc : s.scenarios) {
      const double tau = s.ctx->mean_tau_io_us(sc);
      const auto g = ncs::delay_compensated_gain(*s.ctx, tau);
      a["per_scenario"][sc.name] = {{"tau_io_us", tau}, {"gain_x_u", {g[0], g[1], g[2]}}};
    }
  }
}

void attach_bus_bounds(NcsStudy& s, const json& r) {
  s.bus_response_us.assign(s.scenarios.size(), {});
  if (!r.contains("buses")) return;
  for (std::size_t k = 0; k < s.scenarios.size(); ++k) {
    for (const json& b : r.at("buses")) {
      const std::string& name = s.scenarios[k].name;
      const json& list = b.contains("scenarios") && b.at("scenarios").contains(name) ? b.at("scenarios").at(name) : b.at("messages");
      for (const json& m : list) {
        if (m.at("kind") != "link") continue;
        const json& w = m.at("worst_response_us");
        s.bus_response_us[k][m.at("name").get<std::string>()] = w.is_null() ? std::nullopt : std::optional<double>(w.get<double>());
      }
    }
  }
}

std::string describe_resolution(const json& r) {
  std::ostringstream o;
  const json& p = r.at("plant");
  o << "study file " << r.at("source").get<std::string>() << " (study " << r.at("study").get<std::string>() << ")\n";
  o << "plant: " << p.at("kind").get<std::string>() << ", n = " << p.at("n") << ", m = " << p.at("m") << ", p = " << p.at("p");
  if (p.contains("name")) o << " (" << p.at("name").get<std::string>() << ", h = " << p.at("period_us") << " us)";
  o << "\n";
  for (const json& a : r.at("approaches")) {
    o << "approach " << a.at("name").get<std::string>() << " (" << a.at("kind").get<std::string>()
      << "): " << a.at("design").get<std::string>();
    if (a.contains("lqr_gain")) o << "; L = " << a.at("lqr_gain").dump() << ", closed-loop radius " << a.at("closed_loop_spectral_radius");
    if (a.contains("kalman_gain")) o << "; K = " << a.at("kalman_gain").dump() << ", estimator radius " << a.at("estimator_spectral_radius");
    o << "\n";
    if (a.contains("per_scenario"))
      for (const auto& [sc, g] : a.at("per_scenario").items()) o << "  " << sc << ": " << g.dump() << "\n";
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
  o << "grid: " << r.at("grid").at("approaches") << " approaches x " << r.at("grid").at("scenarios") << " scenarios x "
    << r.at("seeds").at("count") << " seeds = " << r.at("grid").at("runs") << " runs\n";
  return o.str();
}

}  // namespace oneshot::study
