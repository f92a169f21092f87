/// @file ncs_live_relay.cpp
/// @brief The delay relay of a live run (see ncs_live_process.hpp): the engine's links and
///        frame faults between the node processes, over UDP on the loopback.
#include <sys/socket.h>

#include <algorithm>
#include <cstdio>
#include <map>
#include <memory>
#include <stdexcept>
#include <vector>

#include "ncs_live_nodes.hpp"
#include "ncs_live_process.hpp"
#include "oneshot/engine/fault_spec.hpp"
#include "oneshot/engine/frame_faults.hpp"
#include "oneshot/engine/link.hpp"

namespace oneshot::ncs::live {

int run_relay(const LiveRun& r, const std::shared_ptr<const Context>& ctx, int fd, const Clock& c) {
  struct Route {
    std::uint8_t src, dst;
    const char* name;
    std::uint16_t port;
  };
  const Route routes[3] = {{kLiveActuator, kLiveSensor, "as", r.sensor_port},
                           {kLiveSensor, kLiveController, "sc", r.controller_port},
                           {kLiveController, kLiveActuator, "ca", r.actuator_port}};
  std::vector<std::unique_ptr<engine::Link>> links;
  std::vector<std::unique_ptr<engine::LinkFaults>> faults;  // the engine's frame faults, same seed and streams
  const engine::FaultSpec spec = engine::parse_fault_spec(r.inject);
  for (const Route& rt : routes) {
    const engine::LinkConfig cfg = leg(*ctx, r.scenario, r.approach, rt.name);
    links.push_back(std::make_unique<engine::Link>(cfg, r.seed));
    faults.push_back(std::make_unique<engine::LinkFaults>(spec, cfg.name, cfg.frame, r.seed));
  }
  struct Held {
    std::size_t route;
    std::vector<std::uint8_t> bytes;
    std::int64_t arrival;
    long injected;  ///< Line of injected.csv (−1: the frame as sent).
  };
  std::multimap<std::int64_t, Held> queue;  // by release instant; FIFO among equal instants
  LogWriter log(r.dir, "relay");
  std::FILE* injected = spec.empty() ? nullptr : std::fopen((r.dir + "/injected.csv").c_str(), "w");
  if (!spec.empty() && injected == nullptr) throw std::runtime_error(r.dir + "/injected.csv: cannot write");
  long injected_lines = 0;
  const auto record = [&](const std::vector<std::uint8_t>& payload) {  // one line: the payload in hex
    for (std::uint8_t b : payload) std::fprintf(injected, "%02x", b);
    std::fputc('\n', injected);
    return injected_lines++;
  };
  const std::int64_t stop = end_ns(r) + kTailNs;
  std::uint8_t buf[posix::kUdpHeaderBytes + posix::kUdpMaxPayloadBytes + 1];
  while (c.now() < stop) {
    const std::int64_t deadline = queue.empty() ? stop : std::min(stop, queue.begin()->first);
    if (posix::wait_readable(fd, c.t0 + deadline)) {
      for (;;) {
        const ssize_t n = ::recv(fd, buf, sizeof buf, MSG_DONTWAIT);
        if (n < 0) break;
        const std::int64_t t = c.now();
        const auto size = static_cast<std::size_t>(n);
        std::size_t route = 3;
        for (std::size_t i = 0; i < 3 && size >= posix::kUdpHeaderBytes + 4; ++i)
          if (buf[0] == routes[i].src && buf[1] == routes[i].dst) route = i;
        if (route == 3) {
          log.write("drop", t, 0, size > 0 ? buf[0] : 0, size > 1 ? buf[1] : 0, 0, static_cast<double>(size));
          continue;
        }
        const std::vector<std::uint8_t> sent(buf + posix::kUdpHeaderBytes, buf + size);
        std::vector<std::uint8_t> payload = sent;
        std::vector<std::vector<std::uint8_t>> extra;
        faults[route]->apply(engine::SimTime{t}, payload, extra);  // as Network::run_node: faults, then the link
        const auto arrival = links[route]->transmit(engine::SimTime{t});  // the engine's link: delay model, FIFO
        const std::uint32_t k = get_u32(buf + posix::kUdpHeaderBytes);
        if (!arrival) {
          log.write("lost", t, 0, buf[0], buf[1], k);
          continue;
        }
        log.write("in", t, 0, buf[0], buf[1], k, static_cast<double>(arrival->count() - t));
        const auto hold = [&](const std::vector<std::uint8_t>& p, long line) {
          std::vector<std::uint8_t> bytes(buf, buf + posix::kUdpHeaderBytes);
          bytes.insert(bytes.end(), p.begin(), p.end());
          queue.emplace(arrival->count(), Held{route, std::move(bytes), t, line});
        };
        hold(payload, payload == sent ? -1 : record(payload));
        for (const auto& e : extra) hold(e, record(e));
      }
    }
    for (std::int64_t t = c.now(); !queue.empty() && queue.begin()->first <= t; t = c.now()) {
      const auto it = queue.begin();
      const Route& rt = routes[it->second.route];
      const sockaddr_in to = posix::loopback(rt.port);
      const std::uint32_t k = get_u32(it->second.bytes.data() + posix::kUdpHeaderBytes);
      if (it->second.injected >= 0) log.write("inject", t, 0, rt.src, rt.dst, k, static_cast<double>(it->second.injected));
      ::sendto(fd, it->second.bytes.data(), it->second.bytes.size(), MSG_DONTWAIT, reinterpret_cast<const sockaddr*>(&to),
               sizeof to);
      log.write("out", t, 0, rt.src, rt.dst, k, static_cast<double>(it->first - it->second.arrival),
                static_cast<double>(it->first), static_cast<double>(it->second.arrival));
      queue.erase(it);
    }
  }
  if (injected != nullptr) std::fclose(injected);
  engine::FaultCounters total;
  for (const auto& f : faults) total += f->counters();
  write_counters(r, "relay", {"nan", "flip", "dup", "replay", "forge_seq", "skipped"},
                 {double(total.nan), double(total.flip), double(total.dup), double(total.replay), double(total.forge_seq),
                  double(total.skipped)});
  return 0;
}

}  // namespace oneshot::ncs::live
