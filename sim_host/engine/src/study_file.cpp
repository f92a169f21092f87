/// @file study_file.cpp
/// @brief Study files (see study_file.hpp and docs/engine.md).
#include "oneshot/engine/study_file.hpp"

#include <cmath>
#include <filesystem>
#include <set>
#include <sstream>

#include "oneshot/dimension_limits.hpp"
#include "oneshot/util/file_io.hpp"
#include "study_parse_detail.hpp"

namespace oneshot::engine {
namespace {

using nlohmann::json;

std::string at(const std::string& where, std::size_t i) { return where + "[" + std::to_string(i) + "]"; }

const json& array_of(const json& j, const std::string& where, const char* key, bool optional) {
  static const json kEmpty = json::array();
  const auto it = j.find(key);
  if (it == j.end()) {
    if (optional) return kEmpty;
    throw InputError("field '" + where + "." + key + "': missing");
  }
  if (!it->is_array()) throw InputError("field '" + where + "." + key + "': must be an array");
  return *it;
}

TriggerSpec parse_trigger(const json& j, const std::string& f) {
  TriggerSpec t;
  const std::string rule = string_of(j, f, "rule");
  if (rule == "periodic") {
    require_keys(j, f, {"rule", "every"});
    t.rule = TriggerSpec::Rule::kPeriodic;
    t.every = static_cast<std::uint32_t>(integer_in(j, f, "every", 1, 1'000'000, true, 1));
  } else if (rule == "send_on_delta") {
    require_keys(j, f, {"rule", "delta", "time_steps"});
    t.rule = TriggerSpec::Rule::kSendOnDelta;
    const json& d = member(j, f, "delta");
    if (!d.is_array() || d.empty() || d.size() > kMaxOutputs) throw InputError("field '" + f + ".delta': must be an array of 1-4 thresholds");
    for (const json& v : d) {
      if (!v.is_number() || !std::isfinite(v.get<double>()) || v.get<double>() < 0) {
        throw InputError("field '" + f + ".delta': thresholds must be finite and >= 0");
      }
      t.delta.push_back(v.get<double>());
    }
    t.time_steps = static_cast<std::uint32_t>(integer_in(j, f, "time_steps", 0, 100'000'000, true, 0));
  } else if (rule == "mtm") {
    require_keys(j, f, {"rule", "sigma", "delta", "k_max", "k_ref_max"});
    t.rule = TriggerSpec::Rule::kMtm;
    t.sigma = number_in(j, f, "sigma", 0, 1e6);
    t.mtm_delta = number_in(j, f, "delta", 0, 1e12);
    t.k_max = static_cast<std::uint32_t>(integer_in(j, f, "k_max", 0, 100'000'000, true, 0));
    t.k_ref_max = static_cast<std::uint32_t>(integer_in(j, f, "k_ref_max", 0, 100'000'000, true, 0));
  } else {
    throw InputError("field '" + f + ".rule': unknown rule '" + rule + "' (periodic, send_on_delta, mtm)");
  }
  return t;
}

template <typename T>
void unique_names(const std::vector<T>& items, const std::string& f) {
  std::set<std::string> seen;
  for (std::size_t i = 0; i < items.size(); ++i) {
    if (!seen.insert(items[i].name).second) throw InputError("field '" + at(f, i) + ".name': '" + items[i].name + "' used twice");
  }
}

/// The loops of a file with `loops[]` into s.loops: each names its sensor, controller and
/// actuator (declared nodes of those roles, in no other loop); every node in a loop; every
/// link within one loop.
void parse_loops(const json& loops, StudyFile& s) {
  if (loops.empty()) throw InputError("field 'loops': must not be empty (omit it for the one loop of the file)");
  std::map<std::string, std::string> loop_of;  // node -> loop
  for (std::size_t i = 0; i < loops.size(); ++i) {
    const std::string f = at("loops", i);
    require_keys(loops[i], f, {"name", "plant", "sensor", "controller", "actuator"});
    LoopSpec l;
    l.name = string_of(loops[i], f, "name");
    if (l.name.empty() || l.name.find('/') != std::string::npos) throw InputError("field '" + f + ".name': not empty, no '/' (it prefixes stream names)");
    l.plant = detail::parse_plant(member(loops[i], f, "plant"), f + ".plant");
    const std::pair<const char*, std::string*> roles[] = {{"sensor", &l.sensor}, {"controller", &l.controller}, {"actuator", &l.actuator}};
    for (const auto& [role, slot] : roles) {
      const std::string g = f + "." + role;
      *slot = string_of(loops[i], f, role);
      const NodeSpec* n = nullptr;
      for (const NodeSpec& x : s.nodes)
        if (x.name == *slot) n = &x;
      if (n == nullptr) throw InputError("field '" + g + "': no node '" + *slot + "'");
      if (n->role != role) throw InputError("field '" + g + "': node '" + *slot + "' is a " + n->role + ", not a " + role);
      const auto [it, fresh] = loop_of.emplace(*slot, l.name);
      if (!fresh) throw InputError("field '" + g + "': node '" + *slot + "' is already in loop '" + it->second + "'");
    }
    s.loops.push_back(l);
  }
  unique_names(s.loops, "loops");
  for (std::size_t i = 0; i < s.nodes.size(); ++i) {
    if (loop_of.count(s.nodes[i].name) == 0) throw InputError("field '" + at("nodes", i) + "': node '" + s.nodes[i].name + "' is in no loop");
  }
  for (std::size_t i = 0; i < s.links.size(); ++i) {
    const LinkSpec& l = s.links[i];
    if (loop_of.at(l.from) != loop_of.at(l.to)) {
      throw InputError("field '" + at("links", i) + ".to': '" + l.to + "' is in loop '" + loop_of.at(l.to) + "', '" + l.from +
                       "' in loop '" + loop_of.at(l.from) + "' (a link joins two nodes of one loop)");
    }
  }
}

}  // namespace

const NodeSpec& StudyFile::node(const std::string& name) const {
  for (const NodeSpec& n : nodes)
    if (n.name == name) return n;
  throw InputError(source + ": no node '" + name + "'");
}

LinkConfig StudyFile::link_config(const std::string& name, const ScenarioSpec* s) const {
  for (const LinkSpec& l : links) {
    if (l.name != name) continue;
    if (!l.bus.empty()) throw InputError(source + ": link '" + name + "' runs on CAN bus '" + l.bus + "'");
    LinkConfig c{l.name, l.delay, l.loss, l.fifo};
    if (s != nullptr && s->delays.count(name) != 0) c.delay = s->delays.at(name);
    if (s != nullptr && s->losses.count(name) != 0) c.loss = s->losses.at(name);
    return c;
  }
  throw InputError(source + ": no link '" + name + "'");
}

StudyFile parse_study(const std::string& text, const std::string& source, const StudySchema* schema,
                      const std::string& base_dir) {
  const json root = parse_json_strict(text, source);
  try {
    require_keys(root, "study file", {"schema", "study", "description", "plant", "loops", "duration_s", "seeds", "nodes",
                                      "links", "buses", "cpus", "approaches", "scenarios", "reference"});
    StudyFile s;
    s.source = source;
    if (string_of(root, "study file", "schema") != kStudySchemaVersion) {
      throw InputError(std::string("field 'schema': must be \"") + kStudySchemaVersion + "\"");
    }
    s.study = string_of(root, "study file", "study");
    if (schema != nullptr && s.study != schema->study) {
      throw InputError("field 'study': '" + s.study + "' is not the study '" + schema->study + "'");
    }
    s.description = root.contains("description") ? string_of(root, "study file", "description") : std::string();
    const bool several_loops = root.contains("loops");
    if (several_loops && root.contains("plant")) throw InputError("field 'plant': with loops[] each loop has its own (loops[i].plant)");
    if (!several_loops) s.plant = detail::parse_plant(member(root, "study file", "plant"), "plant");
    s.duration_s = number_in(root, "study file", "duration_s", 1e-6, 1e6);
    const json& seeds = member(root, "study file", "seeds");
    require_keys(seeds, "seeds", {"first", "count"});
    s.first_seed = static_cast<std::uint64_t>(integer_in(seeds, "seeds", "first", 0, INT64_MAX, true, 1));
    s.seeds = static_cast<std::size_t>(integer_in(seeds, "seeds", "count", 2, 10'000'000));

    // CPUs first (the nodes name them): the task-file parser, fields under cpus[i].
    const json& cpus = array_of(root, "study file", "cpus", true);
    for (std::size_t i = 0; i < cpus.size(); ++i) {
      const std::string f = at("cpus", i);
      if (!cpus[i].is_object() || !cpus[i].contains("name")) throw InputError("field '" + f + ".name': missing");
      cpu::TaskSet c = cpu::parse_task_set_json(cpus[i], f, base_dir, true);
      c.streams_per_cpu = true;
      for (const cpu::TaskSet& o : s.cpus)
        if (o.name == c.name) throw InputError("field '" + f + ".name': '" + c.name + "' used twice");
      s.cpus.push_back(std::move(c));
    }

    const json& nodes = array_of(root, "study file", "nodes", true);
    std::set<std::int64_t> addresses;
    for (std::size_t i = 0; i < nodes.size(); ++i) {
      const std::string f = at("nodes", i);
      const json& n = nodes[i];
      require_keys(n, f, {"name", "role", "address", "mode", "period_us", "clock_offset_us", "trigger", "cpu", "job"});
      NodeSpec node;
      node.name = string_of(n, f, "name");
      node.role = string_of(n, f, "role");
      if (node.role != "sensor" && node.role != "controller" && node.role != "actuator") {
        throw InputError("field '" + f + ".role': must be sensor, controller or actuator");
      }
      const std::int64_t address = integer_in(n, f, "address", 0, 255);
      if (!addresses.insert(address).second) throw InputError("field '" + f + ".address': used twice");
      node.address = static_cast<std::uint8_t>(address);
      node.mode = string_of(n, f, "mode", true, "timer");
      if (node.mode != "timer" && node.mode != "arrival") throw InputError("field '" + f + ".mode': must be timer or arrival");
      if (node.mode == "timer") node.period = from_us(integer_in(n, f, "period_us", 1, 3'600'000'000));
      if (node.mode == "arrival" && n.contains("period_us")) {
        throw InputError("field '" + f + ".period_us': an arrival-driven node has no period");
      }
      node.clock_offset = from_us(integer_in(n, f, "clock_offset_us", -3'600'000'000, 3'600'000'000, true, 0));
      if (n.contains("trigger")) node.trigger = parse_trigger(n["trigger"], f + ".trigger");
      if (n.contains("cpu")) {
        node.cpu = string_of(n, f, "cpu");
        const cpu::TaskSet* on = nullptr;
        for (const cpu::TaskSet& c : s.cpus)
          if (c.name == node.cpu) on = &c;
        if (on == nullptr) throw InputError("field '" + f + ".cpu': no cpu '" + node.cpu + "' (cpus[].name)");
        if (!n.contains("job")) throw InputError("field '" + f + ".job': missing (the node's job on cpu '" + node.cpu + "')");
        node.job = cpu::parse_node_job(n["job"], f + ".job", node.name, base_dir);
        node.job_exec = n["job"].contains("exec");
        for (const auto* list : {&on->tasks, &on->isrs})
          for (const cpu::TaskSpec& t : *list)
            if (t.name == node.name) throw InputError("field '" + f + ".name': cpu '" + node.cpu + "' has a task or ISR '" + t.name + "'");
      } else if (n.contains("job")) {
        throw InputError("field '" + f + ".job': a job needs a cpu (nodes[].cpu)");
      }
      s.nodes.push_back(node);
    }
    unique_names(s.nodes, "nodes");

    const json& buses = array_of(root, "study file", "buses", true);
    for (std::size_t i = 0; i < buses.size(); ++i) {
      const std::string f = at("buses", i);
      const json& b = buses[i];
      require_keys(b, f, {"name", "bit_rate", "identifiers", "background"});
      BusSpec bus;
      bus.config.name = string_of(b, f, "name");
      bus.config.bit_rate = integer_in(b, f, "bit_rate", 1000, 1'000'000'000);
      if (1'000'000'000 % bus.config.bit_rate != 0) {
        throw InputError("field '" + f + ".bit_rate': must divide 1e9 (a whole number of ns per bit)");
      }
      const std::string ids = string_of(b, f, "identifiers", true, "standard");
      if (ids != "standard" && ids != "extended") throw InputError("field '" + f + ".identifiers': standard or extended");
      bus.config.extended_ids = ids == "extended";
      const json& bg = array_of(b, f, "background", true);
      for (std::size_t k = 0; k < bg.size(); ++k) {
        const std::string g = at(f + ".background", k);
        require_keys(bg[k], g, {"name", "id", "payload_bytes", "period_us", "jitter_us", "deadline_us", "offset_us"});
        CanStream st;
        st.name = string_of(bg[k], g, "name");
        st.id = static_cast<std::uint32_t>(integer_in(bg[k], g, "id", 0, bus.config.extended_ids ? 0x1FFFFFFF : 0x7FF));
        st.payload_bytes = static_cast<std::size_t>(integer_in(bg[k], g, "payload_bytes", 0, 8));
        st.period = from_us(integer_in(bg[k], g, "period_us", 1, 3'600'000'000));
        st.jitter = from_us(integer_in(bg[k], g, "jitter_us", 0, 3'600'000'000, true, 0));
        st.deadline = from_us(integer_in(bg[k], g, "deadline_us", 1, 3'600'000'000, true, st.period.count() / 1000));
        bus.background.push_back(st);
        bus.offsets.push_back(from_us(integer_in(bg[k], g, "offset_us", 0, 3'600'000'000, true, 0)));
      }
      s.buses.push_back(bus);
    }
    for (std::size_t i = 0; i < s.buses.size(); ++i)
      for (std::size_t k = 0; k < i; ++k)
        if (s.buses[i].config.name == s.buses[k].config.name) throw InputError("field '" + at("buses", i) + ".name': used twice");

    const json& links = array_of(root, "study file", "links", true);
    std::map<std::string, std::set<std::uint32_t>> bus_ids;
    for (std::size_t i = 0; i < s.buses.size(); ++i)
      for (const CanStream& st : s.buses[i].background) bus_ids[s.buses[i].config.name].insert(st.id);
    for (std::size_t i = 0; i < links.size(); ++i) {
      const std::string f = at("links", i);
      const json& l = links[i];
      LinkSpec link;
      if (l.is_object() && l.contains("bus")) {
        require_keys(l, f, {"name", "from", "to", "bus", "id"});
      } else {
        require_keys(l, f, {"name", "from", "to", "delay", "loss", "order"});
      }
      link.name = string_of(l, f, "name");
      link.from = string_of(l, f, "from");
      link.to = string_of(l, f, "to");
      s.node(link.from);
      s.node(link.to);
      if (link.from == link.to) throw InputError("field '" + f + ".to': a link joins two different nodes");
      if (l.contains("bus")) {
        link.bus = string_of(l, f, "bus");
        const BusSpec* bus = nullptr;
        for (const BusSpec& b : s.buses)
          if (b.config.name == link.bus) bus = &b;
        if (bus == nullptr) throw InputError("field '" + f + ".bus': no bus '" + link.bus + "'");
        link.id = static_cast<std::uint32_t>(integer_in(l, f, "id", 0, bus->config.extended_ids ? 0x1FFFFFFF : 0x7FF));
        if (!bus_ids[link.bus].insert(link.id).second) throw InputError("field '" + f + ".id': identifier used twice on the bus");
      } else {
        link.delay = parse_delay_model(member(l, f, "delay"), f + ".delay", base_dir);
        link.loss = l.contains("loss") ? parse_loss_model(l["loss"], f + ".loss") : LossModel{};
        const std::string order = string_of(l, f, "order", true, "any");
        if (order != "any" && order != "fifo") throw InputError("field '" + f + ".order': must be any or fifo");
        link.fifo = order == "fifo";
      }
      for (const LinkSpec& o : s.links)
        if (o.from == link.from && o.to == link.to) throw InputError("field '" + f + "': a second link from '" + link.from + "' to '" + link.to + "'");
      s.links.push_back(link);
    }
    unique_names(s.links, "links");
    if (several_loops) parse_loops(array_of(root, "study file", "loops", false), s);

    const json& approaches = array_of(root, "study file", "approaches", false);
    if (approaches.empty()) throw InputError("field 'approaches': must not be empty");
    for (std::size_t i = 0; i < approaches.size(); ++i) {
      const std::string f = at("approaches", i);
      require_keys(approaches[i], f, {"name", "kind", "params"});
      ApproachSpec a;
      a.name = string_of(approaches[i], f, "name");
      a.kind = string_of(approaches[i], f, "kind", true, a.name);
      if (schema != nullptr) {
        bool known = false;
        std::string list;
        for (const std::string& k : schema->approach_kinds) {
          known = known || k == a.kind;
          list += (list.empty() ? "" : ", ") + k;
        }
        if (!known) throw InputError("field '" + f + ".kind': unknown kind '" + a.kind + "' (" + list + ")");
      }
      a.params = detail::parse_params(approaches[i], f, schema != nullptr ? &schema->approach_params : nullptr, &a.words);
      s.approaches.push_back(a);
    }
    unique_names(s.approaches, "approaches");

    if (root.contains("reference")) s.reference = parse_reference(root["reference"], "reference", base_dir);
    const json& scenarios = array_of(root, "study file", "scenarios", false);
    if (scenarios.empty()) throw InputError("field 'scenarios': must not be empty");
    for (std::size_t i = 0; i < scenarios.size(); ++i) {
      const std::string f = at("scenarios", i);
      const json& sc = scenarios[i];
      require_keys(sc, f, {"name", "duration_s", "params", "links", "reference"});
      ScenarioSpec x;
      x.name = string_of(sc, f, "name");
      if (sc.contains("duration_s")) x.duration_s = number_in(sc, f, "duration_s", 1e-6, 1e6);
      x.params = detail::parse_params(sc, f, schema != nullptr ? &schema->scenario_params : nullptr);
      if (sc.contains("params")) {
        for (const auto& item : sc["params"].items()) x.params_given.insert(item.key());
      }
      if (sc.contains("reference")) x.reference = parse_reference(sc["reference"], f + ".reference", base_dir);
      if (sc.contains("links")) {
        const json& over = sc["links"];
        if (!over.is_object()) throw InputError("field '" + f + ".links': must be an object of link overrides");
        for (const auto& item : over.items()) {
          const std::string g = f + ".links." + item.key();
          const LinkSpec* target = nullptr;  // must name a point-to-point link
          for (const LinkSpec& l : s.links)
            if (l.name == item.key()) target = &l;
          if (target == nullptr) throw InputError("field '" + g + "': no link '" + item.key() + "'");
          if (!target->bus.empty()) {
            throw InputError("field '" + g + "': link '" + item.key() + "' runs on CAN bus '" + target->bus +
                             "' (no delay or loss to override)");
          }
          require_keys(item.value(), g, {"delay", "loss"});
          if (item.value().contains("delay")) x.delays[item.key()] = parse_delay_model(item.value()["delay"], g + ".delay", base_dir);
          if (item.value().contains("loss")) x.losses[item.key()] = parse_loss_model(item.value()["loss"], g + ".loss");
        }
      }
      s.scenarios.push_back(x);
    }
    unique_names(s.scenarios, "scenarios");
    return s;
  } catch (const InputError& e) {
    throw InputError(source + ": " + e.what());
  }
}

StudyFile load_study(const std::string& path, const StudySchema* schema) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) throw InputError(path + ": not a readable regular file");
  const std::string text = util::read_text_file_as<InputError>(path, "study file", {}, std::size_t{1} << 26);  // 64 MiB
  return parse_study(text, path, schema, std::filesystem::path(path).parent_path().string());
}

}  // namespace oneshot::engine
