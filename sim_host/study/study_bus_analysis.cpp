/// @file study_bus_analysis.cpp
/// @brief The CAN buses of a study file analysed for `study check` (see study_bus_analysis.hpp).
#include "study_bus_analysis.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iterator>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "ncs_model.hpp"
#include "oneshot/engine/can_analysis.hpp"
#include "oneshot/node/message.hpp"
#include "study_check.hpp"

namespace oneshot::study {
namespace {

using engine::InputError;
using nlohmann::json;

/// The smallest timer period of the loop of node `node` (a file without `loops`: of the
/// file; 0 when no node runs a timer).
engine::Duration loop_period(const engine::StudyFile& f, const std::string& node) {
  const engine::LoopSpec* loop = nullptr;
  for (const engine::LoopSpec& l : f.loops)
    if (l.sensor == node || l.controller == node || l.actuator == node) loop = &l;
  engine::Duration p{0};
  for (const engine::NodeSpec& n : f.nodes) {
    if (loop != nullptr && n.name != loop->sensor && n.name != loop->controller && n.name != loop->actuator) continue;
    if (n.mode == "timer" && (p.count() == 0 || n.period < p)) p = n.period;
  }
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
std::size_t loop_message_bytes(const engine::StudyFile& f, const engine::LinkSpec& link) {
  if (f.study != "ncs") return kLoopFramePayloadBytes;
  // The leg by the roles it joins (a file with several loops names its links freely).
  const std::string from = f.node(link.from).role, to = f.node(link.to).role;
  if (from == "sensor" && to == "controller") return node::encoded_size<double, ncs::kP>();
  if ((from == "controller" && to == "actuator") || (from == "actuator" && to == "sensor")) return node::encoded_size<double, ncs::kM>();
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
              {"message_bytes", 8 * streams[k].leading_frames + streams[k].payload_bytes}, {"period_us", to_us(streams[k].period)},
              {"jitter_us", unbounded_jitter[k] ? json(nullptr) : json(to_us(streams[k].jitter))},
              {"deadline_us", to_us(streams[k].deadline)}, {"transmission_us", to_us(bounds[k].transmission)},
              {"bounded", bounded}, {"schedulable", bounded && bounds[k].schedulable}};
    m["worst_response_us"] = bounded ? json(to_us(bounds[k].response)) : json(nullptr);
    out.push_back(m);
  }
  return out;
}

}  // namespace

json analyze_buses(const engine::StudyFile& f) {
  json out = json::array();
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
      const engine::Duration t = from.mode == "timer" ? from.period : loop_period(f, l.from);
      if (t.count() <= 0) throw InputError("field '" + field + "': link " + l.name + " has no period (no timer node)");
      const std::size_t bytes = loop_message_bytes(f, l);
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
    out.push_back({{"name", bus.config.name}, {"bit_rate", bus.config.bit_rate}, {"load", load}});
    buses.push_back(std::move(x));
  }
  // Every bus under scenario `s`: from every loop message at its transmission time, the
  // jitters and responses until the delays [C, R] stop moving (they only grow); after 64
  // rounds a message still moving is taken unbounded.
  const auto analyze = [&](const engine::ScenarioSpec* s) {
    BusDelays delays;
    for (const Bus& x : buses)
      for (std::size_t k = 0; k < x.on_bus.size(); ++k) delays[x.on_bus[k]->name] = SendWindow{x.message_time[k], x.message_time[k]};
    std::vector<json> found(buses.size());
    for (std::size_t round = 0;; ++round) {
      BusDelays next;
      for (std::size_t b = 0; b < buses.size(); ++b) {
        const Bus& x = buses[b];
        found[b] = bus_messages(x.streams, x.kinds, x.first_link, loop_jitters(f, x.on_bus, s, delays), f.buses[b].config);
        for (std::size_t k = 0; k < x.on_bus.size(); ++k) {
          const json& m = found[b][x.first_link + k];
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
    return found;
  };
  const std::vector<json> base = analyze(nullptr);
  for (std::size_t b = 0; b < buses.size(); ++b) out[b]["messages"] = base[b];
  // A scenario whose link overrides change a loop message's jitter: its own analysis.
  for (const engine::ScenarioSpec& s : f.scenarios) {
    const std::vector<json> own = analyze(&s);
    for (std::size_t b = 0; b < buses.size(); ++b)
      if (own[b] != base[b]) out[b]["scenarios"][s.name] = own[b];
  }
  return out;
}

}  // namespace oneshot::study
