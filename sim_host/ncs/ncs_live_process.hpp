/// @file ncs_live_process.hpp
/// @brief What the processes of a live run share (ncs_live_roles.cpp, ncs_live_relay.cpp):
///        their clock from t0, the end of the run and the tail served after it, the counters
///        file; and the delay relay's process.
#pragma once

#include <cstddef>
#include <cstdint>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "ncs_live.hpp"
#include "ncs_model.hpp"
#include "oneshot/engine/sim_time.hpp"
#include "oneshot/posix/udp_network.hpp"

namespace oneshot::ncs::live {

/// Processes keep serving this long after the end (frames in flight), then exit.
inline constexpr std::int64_t kTailNs = 300'000'000;

/// Time since t0 (ns).
struct Clock {
  std::int64_t t0;  ///< CLOCK_MONOTONIC instant of t = 0 (ns).
  /// Now, since t0 (ns).
  std::int64_t now() const { return posix::monotonic_ns() - t0; }
};

/// The end of the run's scenario (ns since t0).
inline std::int64_t end_ns(const LiveRun& r) {
  return engine::from_seconds(r.scenario.duration_s, "live duration").count();
}

/// DIR/counters_<role>.json: {name: value}.
inline void write_counters(const LiveRun& r, const char* role, const std::vector<std::string>& names,
                           const std::vector<double>& values) {
  nlohmann::json j = nlohmann::json::object();
  for (std::size_t i = 0; i < names.size() && i < values.size(); ++i) j[names[i]] = values[i];
  std::ofstream(r.dir + "/counters_" + role + ".json") << j.dump(1) << "\n";
}

/// The delay relay on socket `fd`: every frame between the nodes through the engine's link of
/// its leg (delay model, loss, FIFO) and frame faults, logged; returns the exit status.
int run_relay(const LiveRun& r, const std::shared_ptr<const Context>& ctx, int fd, const Clock& c);

}  // namespace oneshot::ncs::live
