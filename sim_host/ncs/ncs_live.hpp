/// @file ncs_live.hpp
/// @brief Study `ncs`, live: the same node code as separate processes over UDP loopback.
///
/// Processes (hidden sub-command `oneshot-sim ncs node --role R --run DIR/run.json`):
///   plant      the continuous plant propagated exactly on CLOCK_MONOTONIC; answers the
///              sensor's sampling request with y = C x + v at the instant it reads it, and
///              applies the actuator's command at the instant it reads it.
///   sensor, controller, actuator   SyncSensorNode / SyncControllerNode / SyncActuatorNode
///              (firmware/node) on the POSIX UDP port (hal/posix_udp); the actuator's timer
///              fires at t_k = k h on the shared clock; the controller waits τ_c ~ U[1, 5] ms
///              (stream "compute") before it runs.
///   relay      every frame goes through it: it holds each one for the delay of its link's
///              model (stream link/<as|sc|ca>/delay, the simulation's streams) and forwards it.
/// Every process logs to DIR/<role>.csv: `event,t_ns,clock_us,src,dst,k,v0,v1,v2`
/// (t_ns since the common start t0, clock_us the node clock, doubles in %.17g).
/// `replay` feeds the recorded instants, frames and noise draws back into the engine with
/// the same node code and recomputes the cost.
/// With `--inject SPEC` (docs/faults.md) the relay applies the engine's frame faults
/// (LinkFaults, the run's seed) to every frame it receives, before its delay, and logs
/// each frame it altered or added as `inject` (v0: its line in DIR/injected.csv, which
/// holds its bytes) just before its `out`; a node named by `restart` rebuilds itself at
/// that instant (logged `restart`), losing what its socket held. Every node process
/// writes its counters (ncs_counters.hpp) to DIR/counters_<role>.json, the relay the
/// faults it injected; the summary gathers them.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "ncs_model.hpp"
#include "oneshot/engine/json_fields.hpp"

namespace oneshot::ncs {

/// Node addresses of the live loop (and of the replay and the simulated loop).
inline constexpr std::uint8_t kLiveSensor = 1;
inline constexpr std::uint8_t kLiveController = 2;
inline constexpr std::uint8_t kLiveActuator = 3;

/// What every process of a live run reads (DIR/run.json).
struct LiveRun {
  std::string dir;                ///< Output folder (logs, run.json, summary).
  std::string plant_file;         ///< Plant file (empty: built-in default).
  Approach approach = Approach::kAK;
  Scenario scenario;              ///< Delays, noise, set-point; duration_s is the run length.
  std::uint64_t seed = 1;         ///< Streams: process, measurement, compute, link/*/delay.
  bool noise_free = false;        ///< No process or measurement noise.
  std::string inject;             ///< Fault spec (empty: none).
  std::int64_t t0_ns = 0;         ///< CLOCK_MONOTONIC instant of t = 0.
  std::uint16_t relay_port = 0;   ///< Ports on 127.0.0.1.
  std::uint16_t plant_port = 0;
  std::uint16_t sensor_port = 0;
  std::uint16_t controller_port = 0;
  std::uint16_t actuator_port = 0;
};
/// As JSON, and back (engine::InputError naming the field).
nlohmann::json to_json(const LiveRun& r);
LiveRun live_run_from_json(const nlohmann::json& j, const std::string& source);
/// Reads DIR/run.json.
LiveRun load_live_run(const std::string& dir);

/// One log line.
struct LogRecord {
  std::string event;          ///< e.g. "timer", "send", "recv", "sample", "apply", "in", "out".
  std::int64_t t_ns = 0;      ///< Since t0.
  std::uint32_t clock_us = 0; ///< Node clock.
  int src = 0;                ///< Source address (0: none).
  int dst = 0;                ///< Destination address.
  std::uint32_t k = 0;        ///< Period index / sequence number.
  double v[3] = {};           ///< Event-specific values.
};
/// Reads DIR/<role>.csv; engine::InputError naming the file and line when malformed.
std::vector<LogRecord> read_log(const std::string& dir, const std::string& role);

/// Runs one process of a live run (`role` = plant, sensor, controller, actuator, relay);
/// network socket on `net_fd`, plant link on `io_fd` (-1 when unused). Returns the exit code.
int run_live_role(const std::string& role, const LiveRun& run, int net_fd, int io_fd);

/// Options of `ncs live`.
struct LiveOptions {
  std::string plant_file;
  Approach approach = Approach::kAK;
  Scenario scenario;
  std::uint64_t seed = 1;
  bool noise_free = false;
  std::string inject;          ///< Fault spec (empty: none).
  std::string out_dir;
  std::string executable;      ///< oneshot-sim (the processes are its hidden sub-command).
  std::int64_t startup_ms = 400;  ///< Time the processes get to start before t0.
};
/// Starts the five processes, waits for the end, analyses the logs and replays them;
/// returns the summary (also written to OUT/summary.json).
nlohmann::json run_live(const LiveOptions& o);

/// What the replay returns.
struct ReplayResult {
  double cost = 0;                ///< J of the replay.
  std::uint32_t applied = 0;      ///< Commands applied.
  std::uint32_t late = 0;         ///< Late periods (actuator).
  std::uint32_t missing_frames = 0;   ///< Logged receipts whose frame the replay never sent.
  double max_abs_u_difference = 0;    ///< max |u_replay − u_live| over the applied commands.
};
/// Replays the logs of DIR on the engine with the same node code. `ideal_instants`: the
/// actuator's timer and the plant's applications exactly at t_k = k h and every sample at
/// the sensor's stamp t_s (the delays, frames and draws as recorded): what the run would
/// cost without the host's real-time errors.
ReplayResult replay_live(const std::string& dir, bool ideal_instants = false);

/// Summary of a live run's logs beside its replay (the figures of docs/ncs.md).
nlohmann::json analyse_live(const std::string& dir);

}  // namespace oneshot::ncs

namespace CLI {
class App;
}  // namespace CLI

namespace oneshot::sim {
/// Registers `ncs live`, `ncs replay` and the hidden `ncs node` under the study command.
void add_ncs_live_commands(CLI::App* study);
/// Registers `ncs faults` (ncs_faults.hpp) under the study command.
void add_ncs_faults_command(CLI::App* study);
/// Adds `oneshot-sim ncs stationary` (ncs_stationary.hpp) under the study command.
void add_ncs_stationary_command(CLI::App* study);
}  // namespace oneshot::sim
