/// @file study_loops_map.cpp
/// @brief A study file with several loops (`loops[]`) mapped onto the ncs loop, each loop as
///        the one loop of a file of its own (see study_ncs_runner.hpp: map_ncs_study(), loop_view()).
#include <iterator>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "study_fields.hpp"
#include "study_ncs_runner.hpp"

namespace oneshot::study {
namespace {

using engine::InputError;

/// Replaces in `what` every "'<list>[j]" by "'<list>[index[j]]" (a refusal of a loop's view
/// named in the file's indices).
std::string renumber(std::string what, const std::string& list, const std::vector<std::size_t>& index) {
  for (std::size_t j = 0; j < index.size(); ++j) {
    const std::string from = "'" + list + "[" + std::to_string(j) + "]";
    const std::size_t p = what.find(from);
    if (p == std::string::npos) continue;
    what.replace(p, from.size(), "'" + list + "[" + std::to_string(index[j]) + "]");
    break;  // one field per refusal
  }
  return what;
}

}  // namespace

NcsStudy map_ncs_loops(const engine::StudyFile& file) {
  if (file.study != "ncs") refuse("study", "'" + file.study + "' has no runner yet (study run runs 'ncs' and 'dropping')");
  if (!file.cpus.empty()) refuse("cpus", "a file with several loops (loops[]) runs no node on a CPU");
  for (std::size_t i = 0; i < file.approaches.size(); ++i) {
    const std::string& k = file.approaches[i].kind;
    if (k != "I" && k != "S" && k != "SK" && k != "IK") {
      refuse(at("approaches", i) + ".kind", "a file with several loops (loops[]) runs the sampling loops I, S, SK, IK (not " + k + ")");
    }
  }
  for (std::size_t b = 0; b < file.buses.size(); ++b) {
    bool used = false;
    for (const engine::LinkSpec& l : file.links) used = used || l.bus == file.buses[b].config.name;
    if (!used) refuse(at("buses", b), "no leg of any loop runs on it (its traffic would run on nothing)");
  }
  NcsStudy out;
  for (std::size_t i = 0; i < file.loops.size(); ++i) {
    const engine::LoopSpec& loop = file.loops[i];
    engine::StudyFile v = loop_view(file, i);
    std::vector<std::size_t> node_index, link_index;
    for (const engine::NodeSpec& n : v.nodes)
      for (std::size_t j = 0; j < file.nodes.size(); ++j)
        if (file.nodes[j].name == n.name) node_index.push_back(j);
    for (const engine::LinkSpec& l : v.links)
      for (std::size_t j = 0; j < file.links.size(); ++j)
        if (file.links[j].name == l.name) link_index.push_back(j);
    // The view as the one loop study ncs runs: addresses 1, 2, 3, links named by their leg.
    std::array<std::uint8_t, 3> addresses{};
    std::map<std::string, std::string> leg_of;  // file link name -> leg
    for (engine::NodeSpec& n : v.nodes) {
      const std::size_t r = n.role == "sensor" ? 0 : n.role == "controller" ? 1 : 2;
      addresses[r] = n.address;
      n.address = r == 0 ? ncs::kLiveSensor : r == 1 ? ncs::kLiveController : ncs::kLiveActuator;
    }
    for (std::size_t j = 0; j < v.links.size(); ++j) {
      engine::LinkSpec& l = v.links[j];
      const std::string from = v.node(l.from).role, to = v.node(l.to).role;
      const NcsLeg* leg = nullptr;
      for (const NcsLeg& g : kNcsLegs)
        if (from == g.from && to == g.to) leg = &g;
      if (leg == nullptr) {
        refuse(at("links", link_index[j]), "joins a " + from + " to a " + to + ": the legs of a loop are actuator to sensor, "
                                           "sensor to controller, controller to actuator");
      }
      leg_of[l.name] = leg->name;
      l.name = leg->name;
    }
    for (engine::ScenarioSpec& sc : v.scenarios) {
      std::map<std::string, engine::DelayModel> delays;
      std::map<std::string, engine::LossModel> losses;
      for (const auto& [nm, d] : sc.delays) delays[leg_of.at(nm)] = d;
      for (const auto& [nm, d] : sc.losses) losses[leg_of.at(nm)] = d;
      sc.delays = delays;
      sc.losses = losses;
    }
    const std::vector<engine::BusSpec> buses = v.buses;
    v.buses.clear();  // the loop's buses only (the others are its neighbours')
    for (const engine::BusSpec& b : buses) {
      bool used = false;
      for (const engine::LinkSpec& l : v.links) used = used || l.bus == b.config.name;
      if (used) v.buses.push_back(b);
    }
    // The loop's phase: its sensor's clock offset (the timer of I, S, SK, IK); the controller
    // and the actuator act on arrival, their offsets stay 0. The view runs on one clock.
    engine::Duration offset{0};
    std::size_t offset_node = 0;  // the sensor's index in the file
    for (std::size_t p = 0; p < v.nodes.size(); ++p) {
      engine::NodeSpec& n = v.nodes[p];
      if (n.clock_offset.count() == 0) continue;
      if (n.role != "sensor") {
        refuse(at("nodes", node_index[p]) + ".clock_offset_us",
               "a loop's phase is its sensor's clock offset (the timer of I, S, SK, IK); the " + n.role + " acts on arrival: 0 only");
      }
      offset = n.clock_offset;
      offset_node = node_index[p];
      n.clock_offset = engine::Duration{0};
    }
    NcsStudy part;
    try {
      part = map_ncs_study(v);
    } catch (const InputError& e) {
      std::string what = e.what();
      const std::string prefix = file.source + ": ";
      if (what.rfind(prefix, 0) == 0) what.erase(0, prefix.size());
      what = renumber(renumber(what, "nodes", node_index), "links", link_index);
      for (const auto& [nm, leg] : leg_of) {  // a scenario's override of the leg: the file's link name
        const std::string from = ".links." + leg + "'";
        const std::size_t p = what.find(from);
        if (p != std::string::npos) what.replace(p, from.size(), ".links." + nm + "'");
      }
      if (what.rfind("field 'plant", 0) == 0) what.replace(0, 12, "field '" + at("loops", i) + ".plant");
      if (what.rfind("field 'links':", 0) == 0) what.replace(0, 14, "field '" + at("loops", i) + "': its links:");
      throw InputError(what);
    }
    const std::int64_t h_us = part.ctx->period_us();
    if (offset.count() < 0 || offset.count() % 1000 != 0 || offset.count() / 1000 >= h_us) {
      refuse(at("nodes", offset_node) + ".clock_offset_us", "the loop's phase: its sensor's timer fires at kh + clock_offset_us, "
                                                            "0 <= it < h = " + std::to_string(h_us) + " us (whole us)");
    }
    part.clock_offset_us = offset.count() / 1000;
    part.loop = loop.name;
    part.addresses = addresses;
    for (const auto& [nm, leg] : leg_of) part.link_names[leg] = nm;
    out.loops.push_back(std::move(part));
  }
  for (std::size_t i = 1; i < out.loops.size(); ++i) {
    for (std::size_t k = 0; k < out.loops[0].scenarios.size(); ++k) {
      if (out.loops[i].scenarios[k].duration_s != out.loops[0].scenarios[k].duration_s) {
        refuse(at("scenarios", k) + ".duration_s", "the loops of a run end together");  // one file: never differs
      }
    }
  }
  std::vector<NcsStudy> loops = std::move(out.loops);
  out = loops[0];
  out.loops = std::move(loops);
  out.source = file.source;
  return out;
}


engine::StudyFile loop_view(const engine::StudyFile& file, std::size_t i) {
  const engine::LoopSpec& loop = file.loops.at(i);
  engine::StudyFile v = file;
  v.loops.clear();
  v.cpus.clear();
  v.plant = loop.plant;
  v.nodes.clear();
  for (const engine::NodeSpec& n : file.nodes)
    if (n.name == loop.sensor || n.name == loop.controller || n.name == loop.actuator) v.nodes.push_back(n);
  v.links.clear();
  for (const engine::LinkSpec& l : file.links)
    if (l.from == loop.sensor || l.from == loop.controller || l.from == loop.actuator) v.links.push_back(l);
  for (engine::ScenarioSpec& sc : v.scenarios) {
    const auto mine = [&](const std::string& link) {
      for (const engine::LinkSpec& l : v.links)
        if (l.name == link) return true;
      return false;
    };
    for (auto it = sc.delays.begin(); it != sc.delays.end();) it = mine(it->first) ? std::next(it) : sc.delays.erase(it);
    for (auto it = sc.losses.begin(); it != sc.losses.end();) it = mine(it->first) ? std::next(it) : sc.losses.erase(it);
  }
  return v;
}


}  // namespace oneshot::study
