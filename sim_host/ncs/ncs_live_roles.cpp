/// @file ncs_live_roles.cpp
/// @brief The processes of a live run (see ncs_live.hpp): plant, sensor, controller and
///        actuator on the POSIX UDP port (the delay relay: ncs_live_relay.cpp).
#include <sys/prctl.h>
#include <sys/socket.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <map>
#include <memory>
#include <optional>
#include <stdexcept>

#include "ncs_counters.hpp"
#include "ncs_live_nodes.hpp"
#include "ncs_live_process.hpp"
#include "oneshot/engine/frame_faults.hpp"
#include "oneshot/engine/kernel.hpp"
#include "oneshot/engine/link.hpp"
#include "oneshot/node/sync_actuator_node.hpp"
#include "oneshot/node/sync_controller_node.hpp"
#include "oneshot/node/sync_sensor_node.hpp"
#include "oneshot/posix/udp_network.hpp"

namespace oneshot::ncs {
namespace {

using namespace live;
using posix::wait_readable;
using Plant = engine::ContinuousPlant<kN, kM, kP, 1>;
using UdpBoard = posix::UdpNetwork;

/// A sensor waits this long for the plant's answer before giving the sample up.
constexpr std::int64_t kSampleTimeoutNs = 20'000'000;


/// The restart instants of one node (ns since t0) from the run's fault spec.
struct Restarts {
  std::vector<std::int64_t> at;
  std::size_t next = 0;
  Restarts(const LiveRun& r, const char* node) {
    for (engine::SimTime t : engine::restart_instants(engine::parse_fault_spec(r.inject), node)) at.push_back(t.count());
    std::sort(at.begin(), at.end());
  }
  /// `other`, or the next restart when it comes first.
  std::int64_t deadline(std::int64_t other) const { return next < at.size() ? std::min(other, at[next]) : other; }
  /// True (once) when the next restart is due at `now`.
  bool due(std::int64_t now) {
    if (next >= at.size() || now < at[next]) return false;
    ++next;
    return true;
  }
};

/// A restarting node loses what its socket holds.
void drain(int fd) {
  std::uint8_t buf[posix::kUdpHeaderBytes + posix::kUdpMaxPayloadBytes + 1];
  while (::recv(fd, buf, sizeof buf, MSG_DONTWAIT) >= 0) {
  }
}

/// The node's UDP interface, logging every frame as send/recv with its k (bytes 0–3).
void attach(posix::UdpNetworkState& net, int fd, std::uint8_t address, const LiveRun& r, LogWriter& log, const Clock& c) {
  net.fd = fd;
  net.address = address;
  net.relay = posix::loopback(r.relay_port);
  net.on_frame = [&log, &c, address](bool send, std::uint8_t peer, const std::uint8_t* data, std::size_t size) {
    const std::int64_t t = c.now();
    const std::uint32_t k = size >= 4 ? get_u32(data) : 0;
    if (send) {
      log.write("send", t, clock_us(t), address, peer, k);
    } else {
      log.write("recv", t, clock_us(t), peer, address, k);
    }
  };
}

int run_plant(const LiveRun& r, const std::shared_ptr<const Context>& ctx, int fd, const Clock& c) {
  const Scenario& sc = r.scenario;
  engine::Kernel streams(r.seed);  // the simulation's streams: process, measurement
  Plant plant(plant_config(*ctx, sc, !r.noise_free), streams.stream("process"));
  engine::RandomStream measurement = streams.stream("measurement");
  const auto chol = measurement_cholesky(ctx->controller_design(sc.noise_scale));
  const Ref ref = reference(*ctx, sc);
  plant.set_state(ref.state(0));
  plant.set_reference(ref.state(0), ref.input(0));
  const std::uint64_t half = half_wave_periods(*ctx, sc);
  const std::int64_t h_ns = std::int64_t{ctx->period_us()} * 1000;
  const std::int64_t end = end_ns(r);
  std::uint64_t next_switch = half;
  LogWriter log(r.dir, "plant");
  // Propagates exactly to t, switching the set-point on the kh grid on the way.
  const auto advance = [&](std::int64_t t) {
    for (; static_cast<std::int64_t>(next_switch) * h_ns <= t && static_cast<std::int64_t>(next_switch) * h_ns < end;
         next_switch += half) {
      plant.advance_to(engine::SimTime{static_cast<std::int64_t>(next_switch) * h_ns});
      const auto k = static_cast<node::SequenceNumber>(next_switch);
      plant.set_reference(ref.state(k), ref.input(k));
    }
    plant.advance_to(engine::SimTime{t});
  };
  std::uint8_t buf[64];
  while (wait_readable(fd, c.t0 + end) || c.now() < end) {
    for (;;) {
      sockaddr_in from{};
      socklen_t len = sizeof from;
      const ssize_t n = ::recvfrom(fd, buf, sizeof buf, MSG_DONTWAIT, reinterpret_cast<sockaddr*>(&from), &len);
      if (n < 0) break;
      const std::int64_t t = c.now();
      if (t >= end || t < 0) continue;
      const auto size = static_cast<std::size_t>(n);
      if (size == kSampleRequestBytes && buf[0] == 'S') {
        const std::uint32_t k = get_u32(buf + 1);
        const std::uint32_t sensor_clock = get_u32(buf + 5);
        advance(t);
        OutputVec y = plant.output();
        double n0 = 0, n1 = 0;
        if (!r.noise_free) {
          n0 = measurement.normal();
          n1 = measurement.normal();
          y[0] += chol[0] * n0;
          y[1] += chol[1] * n0 + chol[2] * n1;
        }
        std::uint8_t out[kSampleAnswerBytes];
        out[0] = 'Y';
        put_u32(out + 1, k);
        std::memcpy(out + 5, &y[0], 8);
        std::memcpy(out + 13, &y[1], 8);
        ::sendto(fd, out, sizeof out, MSG_DONTWAIT, reinterpret_cast<const sockaddr*>(&from), len);
        log.write("sample", t, sensor_clock, 0, 0, k, n0, n1);
      } else if (size == kCommandBytes && buf[0] == 'U') {
        const std::uint32_t k = get_u32(buf + 1);
        InputVec u;
        std::memcpy(&u[0], buf + 9, 8);
        advance(t);
        plant.set_input(u);
        log.write("apply", t, get_u32(buf + 5), 0, 0, k, u[0]);
      } else {
        log.write("bad", t, 0, 0, 0, 0, static_cast<double>(size));
      }
    }
    if (c.now() >= end) break;
  }
  advance(end);
  log.write("end", end, clock_us(end), 0, 0, 0, plant.cost().total());
  return 0;
}

int run_sensor(const LiveRun& r, const std::shared_ptr<const Context>& ctx, int net_fd, int io_fd, const Clock& c) {
  const std::int32_t late_us = r.approach == Approach::kAKl ? ctx->worst_chain_us(r.scenario) : 0;
  LogWriter log(r.dir, "sensor");
  posix::UdpNetworkState net;
  attach(net, net_fd, kLiveSensor, r, log, c);
  std::uint32_t request_k = 0;
  auto logged = net.on_frame;
  net.on_frame = [&](bool send, std::uint8_t peer, const std::uint8_t* d, std::size_t n) {
    if (!send && n >= 4) request_k = get_u32(d);
    logged(send, peer, d, n);
  };
  posix::ScopedUdpNetwork scope(net);
  std::optional<node::SyncSensorNode<UdpBoard, double, kP, kM>> sensor(std::in_place, kLiveController, late_us);
  check_requests(*ctx, *sensor);
  Restarts restarts(r, "sensor");
  double restarted = 0;
  const sockaddr_in plant = posix::loopback(r.plant_port);
  const std::int64_t stop = end_ns(r) + kTailNs;
  bool pending = false;
  std::int64_t at_ns = 0;
  std::uint32_t pending_k = 0;
  while (c.now() < stop) {
    const bool readable = wait_readable(net_fd, c.t0 + restarts.deadline(pending ? at_ns : stop));
    if (restarts.due(c.now())) {
      drain(net_fd);
      sensor.emplace(kLiveController, late_us);
      check_requests(*ctx, *sensor);
      pending = false;
      ++restarted;
      log.write("restart", c.now(), clock_us(c.now()), 0, kLiveSensor, 0);
      continue;
    }
    if (readable) {
      const std::int64_t t = c.now();
      log.write("invoke", t, clock_us(t), 0, kLiveSensor, 0);
      McuInstant at;
      if (sensor->on_receive(McuInstant(clock_us(t)), at)) {
        pending = true;
        pending_k = request_k;
        at_ns = t + (at - McuInstant(clock_us(t))) * 1000;
      }
    }
    if (!pending || c.now() < at_ns) continue;
    pending = false;
    const std::int64_t t = c.now();
    const std::uint32_t clk = clock_us(t);
    std::uint8_t req[kSampleRequestBytes] = {'S'};
    put_u32(req + 1, pending_k);
    put_u32(req + 5, clk);
    ::sendto(io_fd, req, sizeof req, MSG_DONTWAIT, reinterpret_cast<const sockaddr*>(&plant), sizeof plant);
    bool answered = false;
    OutputVec y;
    while (!answered && wait_readable(io_fd, c.t0 + t + kSampleTimeoutNs)) {
      std::uint8_t ans[64];
      const ssize_t n = ::recv(io_fd, ans, sizeof ans, MSG_DONTWAIT);
      if (n == static_cast<ssize_t>(kSampleAnswerBytes) && ans[0] == 'Y' && get_u32(ans + 1) == pending_k) {
        std::memcpy(&y[0], ans + 5, 8);
        std::memcpy(&y[1], ans + 13, 8);
        answered = true;
      }
    }
    if (!answered) {
      log.write("sample_timeout", c.now(), clk, 0, 0, pending_k);
      continue;
    }
    // A report the interface refuses is counted in the sensor's statistics (logged below).
    static_cast<void>(sensor->on_sample(McuInstant(clk), y));
  }
  const auto& s = sensor->statistics();
  log.write("stats", c.now(), 0, 0, 0, 0, s.requests, s.stale, s.refused);
  write_counters(r, "sensor", concat(sync_sensor_counter_names(), {"sensor.restarts"}),
                 concat(sync_sensor_counters(*sensor), {restarted}));
  log_refusals(log, c.now(), s, s.stale);
  return 0;
}

template <typename Est>
int controller_loop(const LiveRun& r, const Context& ctx, Est est, int net_fd, const Clock& c) {
  LogWriter log(r.dir, "controller");
  posix::UdpNetworkState net;
  attach(net, net_fd, kLiveController, r, log, c);
  posix::ScopedUdpNetwork scope(net);
  const Design d = ctx.controller_design(r.scenario.noise_scale);
  InputVec u_min, u_max;
  for (std::size_t j = 0; j < kM; ++j) {
    u_min[j] = ctx.design().u_min[j];
    u_max[j] = ctx.design().u_max[j];
  }
  using Ctrl = node::SyncControllerNode<UdpBoard, Est, Ref, double, kN, kP, kM>;
  std::optional<Ctrl> ctrl(std::in_place, kLiveActuator, d.l, u_min, u_max, est, reference(ctx, r.scenario));
  check_reports(ctx, *ctrl);
  Restarts restarts(r, "controller");
  double restarted = 0;
  engine::RandomStream compute = engine::Kernel(r.seed).stream("compute");
  const std::int64_t stop = end_ns(r) + kTailNs;
  while (c.now() < stop) {
    const bool readable = wait_readable(net_fd, c.t0 + restarts.deadline(stop));
    if (restarts.due(c.now())) {
      drain(net_fd);
      ctrl.emplace(kLiveActuator, d.l, u_min, u_max, est, reference(ctx, r.scenario));
      check_reports(ctx, *ctrl);
      ++restarted;
      log.write("restart", c.now(), clock_us(c.now()), 0, kLiveController, 0);
      continue;
    }
    if (!readable) continue;
    // τ_c ~ U[1, 5] ms between the arrival and the computation (brief §3).
    const std::int64_t tau_c = compute.uniform_int(ctx.timing().compute_min_us, ctx.timing().compute_max_us) * 1000;
    wait_readable(-1, c.t0 + c.now() + tau_c);
    const std::int64_t t = c.now();
    log.write("invoke", t, clock_us(t), 0, kLiveController, 0);
    ctrl->on_receive(McuInstant(clock_us(t)));
    const auto x = ctrl->estimator().estimate();
    log.write("estimate", c.now(), 0, 0, 0, ctrl->last_k(), x[0], x[1], ctrl->last_command()[0]);
  }
  const auto& s = ctrl->statistics();
  log.write("stats", c.now(), 0, 0, 0, 0, s.computations, s.saturated, s.faults);
  write_counters(r, "controller", concat(sync_controller_counter_names(), {"controller.restarts"}),
                 concat(sync_controller_counters(*ctrl), {restarted}));
  log_refusals(log, c.now(), s, s.stale);
  log.write("resets", c.now(), 0, 0, 0, 0, s.estimator_resets, s.withheld);
  return 0;
}

int run_controller(const LiveRun& r, const std::shared_ptr<const Context>& ctx, int net_fd, const Clock& c) {
  const Design d = ctx->controller_design(r.scenario.noise_scale);
  const Disc disc(ctx->discretizer_model(r.scenario.noise_scale));
  int code = 1;
  with_sync_estimator(*ctx, r.scenario, r.approach, d, disc,
                      [&](auto est, std::int32_t) { code = controller_loop(r, *ctx, est, net_fd, c); });
  return code;
}

int run_actuator(const LiveRun& r, const std::shared_ptr<const Context>& ctx, int net_fd, int io_fd, const Clock& c) {
  LogWriter log(r.dir, "actuator");
  posix::UdpNetworkState net;
  attach(net, net_fd, kLiveActuator, r, log, c);
  posix::ScopedUdpNetwork scope(net);
  std::optional<node::SyncActuatorNode<UdpBoard, double, kM>> act(std::in_place, kLiveSensor, InputVec{});
  check_commands(*ctx, *act);
  Restarts restarts(r, "actuator");
  double restarted = 0;
  std::uint32_t n0 = 0;  // timer index of the actuator's power-on: its period index is n − n0
  bool fresh = false;
  const sockaddr_in plant = posix::loopback(r.plant_port);
  const std::int64_t h_ns = std::int64_t{ctx->period_us()} * 1000;
  const auto h_us = static_cast<std::uint32_t>(ctx->period_us());
  const std::int64_t end = end_ns(r);
  for (std::uint32_t n = 0; std::int64_t{n} * h_ns < end; ++n) {
    const std::int64_t due = std::int64_t{n} * h_ns;
    for (;;) {
      const bool readable = wait_readable(net_fd, c.t0 + restarts.deadline(due));
      if (restarts.due(c.now())) {
        drain(net_fd);
        act.emplace(kLiveSensor, InputVec{});
        check_commands(*ctx, *act);
        fresh = true;
        ++restarted;
        log.write("restart", c.now(), clock_us(c.now()), 0, kLiveActuator, n);
        continue;
      }
      if (!readable) break;
      const std::int64_t t = c.now();
      log.write("invoke", t, clock_us(t), 0, kLiveActuator, 0);
      act->on_receive();
    }
    const std::int64_t t = c.now();
    const std::uint32_t clk = clock_us(t);
    log.write("timer", t, clk, 0, 0, n);
    if (fresh) {  // the restarted actuator's first timer is its k = 0
      fresh = false;
      n0 = n;
    }
    // The timer is periodic: t_{k+1} = (k + 1) h on the shared clock, whatever the wake-up jitter.
    if (n == n0) {
      act->start(McuInstant((n + 1) * h_us));
    } else {
      act->on_timer(n - n0, McuInstant((n + 1) * h_us));
    }
    InputVec u;
    if (act->take_output(u)) {
      std::uint8_t cmd[kCommandBytes] = {'U'};
      put_u32(cmd + 1, n);
      put_u32(cmd + 5, clk);
      std::memcpy(cmd + 9, &u[0], 8);
      ::sendto(io_fd, cmd, sizeof cmd, MSG_DONTWAIT, reinterpret_cast<const sockaddr*>(&plant), sizeof plant);
      log.write("command", c.now(), clk, 0, 0, n, u[0]);
    }
  }
  const auto& s = act->statistics();
  log.write("stats", c.now(), 0, 0, 0, 0, s.late, act->refused());
  log_refusals(log, c.now(), s, s.stale);
  write_counters(r, "actuator", concat(actuator_counter_names(), {"actuator.restarts"}),
                 concat(actuator_counters(*act), {restarted}));
  return 0;
}

}  // namespace

int run_live_role(const std::string& role, const LiveRun& run, int net_fd, int io_fd) {
  const Clock c{run.t0_ns};
  for (int fd : {net_fd, io_fd})
    if (fd >= 0) posix::set_nonblocking(fd);
  const auto ctx = Context::load_board(run.plant_file);  // the design step runs before t0
  ::prctl(PR_SET_TIMERSLACK, 1UL, 0UL, 0UL, 0UL);  // wake-ups as close to the deadline as the kernel can
  const auto start = [&]() { wait_readable(-1, run.t0_ns); };  // everything starts at t0
  if (role == "plant") return start(), run_plant(run, ctx, net_fd, c);
  if (role == "sensor") return start(), run_sensor(run, ctx, net_fd, io_fd, c);
  if (role == "controller") return start(), run_controller(run, ctx, net_fd, c);
  if (role == "actuator") return start(), run_actuator(run, ctx, net_fd, io_fd, c);
  if (role == "relay") return start(), live::run_relay(run, ctx, net_fd, c);
  throw std::invalid_argument("ncs node: unknown role '" + role + "' (plant, sensor, controller, actuator, relay)");
}

}  // namespace oneshot::ncs
