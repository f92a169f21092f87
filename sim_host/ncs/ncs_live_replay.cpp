/// @file ncs_live_replay.cpp
/// @brief Replay of a live run on the engine (see ncs_live.hpp).
///
/// The kernel runs, at the recorded instants (ns since t0), every invocation of the three
/// nodes (same node code, host simulation port): the actuator's timer interrupts and
/// receptions, the sensor's receptions, the controller's computations, each with the node
/// clock it read and the frames it consumed (delivered from the replay's own sends, matched
/// by source, destination and k, so the recorded delays and the relay's order are kept);
/// the plant's samples (recorded measurement-noise draws) and applications at the instants
/// the plant process read them, the set-point switches, the end. Process noise comes from
/// the same seeded stream with the same sequence of propagation instants, hence the same
/// draws. The commands are recomputed, not copied: the replay's cost checks the live one.
/// With ideal instants the process-noise draws are the same normals over slightly different
/// intervals (paired, not identical). A faulted run: the frames the relay altered or added
/// are delivered with their recorded bytes (DIR/injected.csv) in the relay's order for
/// their (source, destination, k), and the recorded restarts rebuild the node.
#include <algorithm>
#include <cmath>
#include <deque>
#include <fstream>
#include <map>
#include <optional>
#include <tuple>

#include "ncs_live_nodes.hpp"
#include "oneshot/engine/kernel.hpp"
#include "oneshot/host/host_network.hpp"
#include "oneshot/node/sync_actuator_node.hpp"
#include "oneshot/node/sync_controller_node.hpp"
#include "oneshot/node/sync_sensor_node.hpp"

namespace oneshot::ncs {
namespace {

using namespace live;
using ReplayBoard = host::HostNetwork;
using Plant = engine::ContinuousPlant<kN, kM, kP, 1>;
using engine::EventClass;
using engine::SimTime;

/// One recorded call into a node and the frames it consumed.
struct Invocation {
  std::uint8_t node = 0;
  bool timer = false;        ///< Actuator timer interrupt (else: reception / computation).
  bool restart = false;      ///< The node restarts.
  std::int64_t t_ns = 0;
  std::uint32_t clock = 0;
  std::uint32_t k = 0;       ///< Timer: period index.
  std::vector<std::pair<int, std::uint32_t>> frames;  ///< (source, k) consumed.
};

void collect_invocations(const std::vector<LogRecord>& log, std::uint8_t node, std::vector<Invocation>& out) {
  Invocation* cur = nullptr;
  for (const LogRecord& r : log) {
    if (r.event == "invoke" || r.event == "timer" || r.event == "restart") {
      out.push_back(Invocation{node, r.event == "timer", r.event == "restart", r.t_ns, r.clock_us, r.k, {}});
      cur = &out.back();
    } else if (r.event == "recv") {
      if (cur == nullptr) throw engine::InputError("ncs replay: a receipt before any invocation of node " + std::to_string(node));
      cur->frames.emplace_back(r.src, r.k);
    } else if (r.event != "send") {
      cur = nullptr;  // receipts belong to the invocation just before them
    }
  }
}

using Key = std::tuple<int, int, std::uint32_t>;

/// Per (source, destination, k), in the relay's order: −1 for a frame forwarded as sent,
/// else its line of injected.csv.
std::map<Key, std::deque<long>> relay_order(const std::vector<LogRecord>& relay) {
  std::map<Key, std::deque<long>> order;
  long pending = -1;
  for (const LogRecord& r : relay) {
    if (r.event == "inject") {
      pending = static_cast<long>(r.v[0]);
    } else if (r.event == "out") {
      order[{r.src, r.dst, r.k}].push_back(pending);
      pending = -1;
    }
  }
  return order;
}

/// The payloads of DIR/injected.csv (hex, one per line); none when the file is absent.
std::vector<std::vector<std::uint8_t>> read_injected(const std::string& dir) {
  std::vector<std::vector<std::uint8_t>> out;
  std::ifstream in(dir + "/injected.csv");
  std::string line;
  while (std::getline(in, line)) {
    std::vector<std::uint8_t> b;
    for (std::size_t i = 0; i + 1 < line.size(); i += 2) {
      b.push_back(static_cast<std::uint8_t>(std::stoul(line.substr(i, 2), nullptr, 16)));
    }
    out.push_back(std::move(b));
  }
  return out;
}

}  // namespace

ReplayResult replay_live(const std::string& dir, bool ideal_instants) {
  const LiveRun run = load_live_run(dir);
  const auto ctx = Context::load_board(run.plant_file);
  const Scenario& sc = run.scenario;
  const Design design = ctx->controller_design(sc.noise_scale);
  const Disc disc(ctx->discretizer_model(sc.noise_scale));
  const std::vector<LogRecord> plant_log = read_log(dir, "plant");
  std::vector<Invocation> inv;
  collect_invocations(read_log(dir, "actuator"), kLiveActuator, inv);
  collect_invocations(read_log(dir, "sensor"), kLiveSensor, inv);
  collect_invocations(read_log(dir, "controller"), kLiveController, inv);
  std::map<Key, std::deque<long>> order = relay_order(read_log(dir, "relay"));
  const std::vector<std::vector<std::uint8_t>> injected = read_injected(dir);
  const auto chol = measurement_cholesky(design);
  const Ref ref = reference(*ctx, sc);
  const std::int64_t h_ns = std::int64_t{ctx->period_us()} * 1000;
  const auto h_us = static_cast<std::uint32_t>(ctx->period_us());
  const SimTime end = engine::from_seconds(sc.duration_s, "live duration");
  InputVec u_min, u_max;
  for (std::size_t j = 0; j < kM; ++j) {
    u_min[j] = ctx->design().u_min[j];
    u_max[j] = ctx->design().u_max[j];
  }
  ReplayResult result;
  with_sync_estimator(*ctx, sc, run.approach, design, disc, [&](auto est, std::int32_t late_us) {
    using Est = decltype(est);
    engine::Kernel kernel(run.seed);
    Plant plant(plant_config(*ctx, sc, !run.noise_free), kernel.stream("process"));
    plant.set_state(ref.state(0));
    plant.set_reference(ref.state(0), ref.input(0));
    host::HostNetworkState net[4];
    for (std::uint8_t a = 1; a <= 3; ++a) net[a].address = a;
    std::optional<node::SyncActuatorNode<ReplayBoard, double, kM>> act(std::in_place, kLiveSensor, InputVec{});
    std::optional<node::SyncSensorNode<ReplayBoard, double, kP, kM>> sensor(std::in_place, kLiveController, late_us);
    using Ctrl = node::SyncControllerNode<ReplayBoard, Est, Ref, double, kN, kP, kM>;
    std::optional<Ctrl> ctrl(std::in_place, kLiveActuator, design.l, u_min, u_max, est, ref);
    check_requests(*ctx, *sensor);
    check_reports(*ctx, *ctrl);
    check_commands(*ctx, *act);
    std::uint32_t n0 = 0;  // the actuator's power-on timer index (as in the live actuator)
    bool fresh = false;
    std::map<Key, std::vector<std::uint8_t>> sent;
    std::map<std::uint32_t, InputVec> commands;  // the replay's actuator output per period
    const auto collect = [&](host::HostNetworkState& s) {
      for (auto& f : s.outbox) {
        const std::uint32_t k = f.bytes.size() >= 4 ? get_u32(f.bytes.data()) : 0;
        sent[{f.source, f.destination, k}] = std::move(f.bytes);
      }
      s.outbox.clear();
    };
    const auto node_h = kernel.add_handler("node", [&](std::uint64_t i) {
      const Invocation& v = inv[i];
      host::HostNetworkState& s = net[v.node];
      if (v.restart) {
        if (v.node == kLiveSensor) {
          sensor.emplace(kLiveController, late_us);
          check_requests(*ctx, *sensor);
        }
        if (v.node == kLiveController) {
          ctrl.emplace(kLiveActuator, design.l, u_min, u_max, est, ref);
          check_reports(*ctx, *ctrl);
        }
        if (v.node == kLiveActuator) {
          act.emplace(kLiveSensor, InputVec{});
          check_commands(*ctx, *act);
          fresh = true;
        }
        return;
      }
      for (const auto& [src, k] : v.frames) {
        auto& q = order[{src, v.node, k}];
        const long line = q.empty() ? -1 : q.front();
        if (!q.empty()) q.pop_front();
        if (line >= 0 && static_cast<std::size_t>(line) < injected.size()) {
          s.deliver(host::Frame{static_cast<std::uint8_t>(src), v.node, injected[static_cast<std::size_t>(line)]});
          continue;
        }
        const auto it = sent.find({src, v.node, k});
        if (it == sent.end()) {
          ++result.missing_frames;
          continue;
        }
        s.deliver(host::Frame{static_cast<std::uint8_t>(src), v.node, it->second});
      }
      {
        host::ScopedHostNetwork scope(s);
        const McuInstant now(v.clock);
        if (v.node == kLiveSensor) {
          McuInstant at;
          (void)sensor->on_receive(now, at);
        } else if (v.node == kLiveController) {
          ctrl->on_receive(now);
        } else if (!v.timer) {
          act->on_receive();
        } else {
          if (fresh) {
            fresh = false;
            n0 = v.k;
          }
          if (v.k == n0) {
            act->start(McuInstant((v.k + 1) * h_us));
          } else {
            act->on_timer(v.k - n0, McuInstant((v.k + 1) * h_us));
          }
          InputVec u;
          if (act->take_output(u)) {
            commands[v.k] = u;
            if (ideal_instants) {  // applied at t_k itself
              plant.advance_to(kernel.now());
              plant.set_input(u);
              ++result.applied;
            }
          }
        }
      }
      collect(s);
    });
    double max_du = 0;
    const auto plant_h = kernel.add_handler("plant", [&](std::uint64_t i) {
      const LogRecord& r = plant_log[i];
      plant.advance_to(kernel.now());
      if (r.event == "sample") {
        OutputVec y = plant.output();
        if (!run.noise_free) {
          y[0] += chol[0] * r.v[0];
          y[1] += chol[1] * r.v[0] + chol[2] * r.v[1];
        }
        host::ScopedHostNetwork scope(net[kLiveSensor]);
        (void)sensor->on_sample(McuInstant(r.clock_us), y);
        collect(net[kLiveSensor]);
      } else {  // apply
        const auto it = commands.find(r.k);
        if (it == commands.end()) {
          ++result.missing_frames;
          return;
        }
        plant.set_input(it->second);
        ++result.applied;
        max_du = std::fmax(max_du, std::fabs(it->second[0] - r.v[0]));
      }
    });
    const auto sw = kernel.add_handler("setpoint", [&](std::uint64_t k) {
      plant.advance_to(kernel.now());
      plant.set_reference(ref.state(static_cast<node::SequenceNumber>(k)), ref.input(static_cast<node::SequenceNumber>(k)));
    });
    const std::uint64_t half = half_wave_periods(*ctx, sc);
    for (std::uint64_t k = half; SimTime{h_ns * static_cast<std::int64_t>(k)} < end; k += half) {
      kernel.schedule(SimTime{h_ns * static_cast<std::int64_t>(k)}, EventClass::kEnvironment, sw, k);
    }
    const auto end_h = kernel.add_handler("end", [&](std::uint64_t) { plant.advance_to(kernel.now()); });
    kernel.schedule(end, EventClass::kEnd, end_h);
    for (std::size_t i = 0; i < plant_log.size(); ++i) {
      const LogRecord& r = plant_log[i];
      if (r.event == "sample") {
        // Ideal: sampled at the sensor's stamp t_s (its clock when it asked), not when the plant read the request.
        const SimTime at{ideal_instants ? std::int64_t{r.clock_us} * 1000 : r.t_ns};
        if (at < end) kernel.schedule(at, EventClass::kSample, plant_h, i);
      } else if (r.event == "apply" && !ideal_instants && SimTime{r.t_ns} < end) {
        kernel.schedule(SimTime{r.t_ns}, EventClass::kActuation, plant_h, i);
      }
    }
    for (std::size_t i = 0; i < inv.size(); ++i) {
      const bool timer = inv[i].timer;
      std::int64_t at_ns = ideal_instants && timer ? std::int64_t{inv[i].k} * h_ns : inv[i].t_ns;
      // An actuator restart comes before the timer it logged (k): kept so at ideal instants.
      const bool act_restart = inv[i].restart && inv[i].node == kLiveActuator;
      if (ideal_instants && act_restart) at_ns = std::min(at_ns, std::int64_t{inv[i].k} * h_ns);
      const EventClass cls = timer ? EventClass::kActuation : act_restart ? EventClass::kEnvironment : EventClass::kCompute;
      if (at_ns >= 0 && SimTime{at_ns} < end) kernel.schedule(SimTime{at_ns}, cls, node_h, i);
    }
    kernel.run_until(end);
    result.cost = plant.cost().total();
    result.late = act->statistics().late;
    result.max_abs_u_difference = max_du;
  });
  return result;
}

}  // namespace oneshot::ncs
