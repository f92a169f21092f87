/// @file ncs_live_test.cpp
/// @brief Live part of study `ncs`: the POSIX UDP port round-trips frames and drives the
///        firmware's sensor node; a short five-process run leaves consistent logs, its relay
///        applied the engine's delay draws, and its replay reproduces the live cost (and
///        moves when a recorded noise draw is changed); a faulted run (--inject) completes,
///        records its injected frames and restarts, and its replay reproduces it. No
///        assertion on real-time figures.
#include <gtest/gtest.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "ncs_live.hpp"
#include "ncs_live_nodes.hpp"
#include "ncs_loop.hpp"
#include "oneshot/engine/frame_faults.hpp"
#include "oneshot/engine/link.hpp"
#include "oneshot/node/sync_sensor_node.hpp"
#include "oneshot/posix/udp_network.hpp"
#include "support/build_flavor.hpp"
#include "support/temp_files.hpp"

#ifndef ONESHOT_SIM_PATH
#error "ONESHOT_SIM_PATH must name the oneshot-sim executable"
#endif

namespace oneshot::ncs {
namespace {

using posix::monotonic_ns;

/// Closes a descriptor at scope exit.
struct Fd {
  int fd;
  ~Fd() { ::close(fd); }
};

constexpr std::int64_t kWaitNs = 2'000'000'000;  // generous: loopback delivery is immediate

TEST(NcsLiveUdp, RoundTripsFramesThroughTheRelayAddress) {
  Fd node{posix::open_loopback_socket()};
  Fd relay{posix::open_loopback_socket()};
  posix::UdpNetworkState st;
  st.fd = node.fd;
  st.address = 7;
  st.relay = posix::loopback(posix::bound_port(relay.fd));
  std::vector<std::pair<bool, std::size_t>> logged;
  st.on_frame = [&](bool send, std::uint8_t, const std::uint8_t*, std::size_t n) { logged.emplace_back(send, n); };
  posix::ScopedUdpNetwork scope(st);
  using Net = posix::UdpNetwork::Net;
  std::uint8_t buf[300];
  std::uint8_t src = 0;
  EXPECT_EQ(Net::receive(src, buf, sizeof buf), 0u);  // nonblocking: nothing waiting
  const std::uint8_t payload[5] = {1, 2, 3, 4, 5};
  ASSERT_TRUE(Net::send(9, payload, sizeof payload));
  ASSERT_TRUE(posix::wait_readable(relay.fd, monotonic_ns() + kWaitNs));
  std::uint8_t wire[300];
  ASSERT_EQ(::recv(relay.fd, wire, sizeof wire, 0), 7);
  EXPECT_EQ(wire[0], 7);  // source
  EXPECT_EQ(wire[1], 9);  // destination
  EXPECT_EQ(std::vector<std::uint8_t>(wire + 2, wire + 7), std::vector<std::uint8_t>(payload, payload + 5));
  // Relay → node: a frame for another address is refused and counted; ours is received.
  const sockaddr_in to = posix::loopback(posix::bound_port(node.fd));
  const std::uint8_t other[4] = {3, 8, 42, 43};
  const std::uint8_t ours[4] = {3, 7, 44, 45};
  ASSERT_EQ(::sendto(relay.fd, other, 4, 0, reinterpret_cast<const sockaddr*>(&to), sizeof to), 4);
  ASSERT_EQ(::sendto(relay.fd, ours, 4, 0, reinterpret_cast<const sockaddr*>(&to), sizeof to), 4);
  ASSERT_TRUE(posix::wait_readable(node.fd, monotonic_ns() + kWaitNs));
  std::size_t n = 0;
  for (std::int64_t until = monotonic_ns() + kWaitNs; n == 0 && monotonic_ns() < until;) n = Net::receive(src, buf, sizeof buf);
  ASSERT_EQ(n, 2u);
  EXPECT_EQ(src, 3);
  EXPECT_EQ(buf[0], 44);
  EXPECT_EQ(buf[1], 45);
  EXPECT_EQ(st.bad_frames, 1u);
  // Too large for the port: refused, counted, nothing sent.
  const std::vector<std::uint8_t> big(posix::kUdpMaxPayloadBytes + 1, 0);
  EXPECT_FALSE(Net::send(9, big.data(), big.size()));
  EXPECT_EQ(st.refused_sends, 1u);
  ASSERT_EQ(logged.size(), 2u);
  EXPECT_TRUE(logged[0].first);
  EXPECT_FALSE(logged[1].first);
}

TEST(NcsLiveUdp, DrivesTheFirmwareSensorNode) {
  Fd node{posix::open_loopback_socket()};
  Fd relay{posix::open_loopback_socket()};
  posix::UdpNetworkState st;
  st.fd = node.fd;
  st.address = kLiveSensor;
  st.relay = posix::loopback(posix::bound_port(relay.fd));
  posix::ScopedUdpNetwork scope(st);
  node::SyncSensorNode<posix::UdpNetwork, double, kP, kM> sensor(kLiveController, 0);
  node::ActuationRequest<double, kM> req;
  req.k = 5;
  req.t_k = McuInstant(250000);
  req.u_applied[0] = -0.25;
  std::uint8_t wire[2 + node::kMaxMessageBytes] = {kLiveActuator, kLiveSensor};
  const std::size_t n = node::encode(req, wire + 2);
  const sockaddr_in to = posix::loopback(posix::bound_port(node.fd));
  ASSERT_EQ(::sendto(relay.fd, wire, n + 2, 0, reinterpret_cast<const sockaddr*>(&to), sizeof to), static_cast<ssize_t>(n + 2));
  ASSERT_TRUE(posix::wait_readable(node.fd, monotonic_ns() + kWaitNs));
  McuInstant at;
  ASSERT_TRUE(sensor.on_receive(McuInstant(210000), at));
  EXPECT_EQ(at.ticks(), 210000u);
  Vector<double, kP> y;
  y[0] = 0.5;
  y[1] = -1.5;
  ASSERT_EQ(sensor.on_sample(McuInstant(210010), y), node::ReportResult::kSent);
  ASSERT_TRUE(posix::wait_readable(relay.fd, monotonic_ns() + kWaitNs));
  std::uint8_t got[300];
  const ssize_t m = ::recv(relay.fd, got, sizeof got, 0);
  ASSERT_GT(m, 2);
  EXPECT_EQ(got[0], kLiveSensor);
  EXPECT_EQ(got[1], kLiveController);
  node::SampleReport<double, kP, kM> rep;
  ASSERT_EQ(node::decode(got + 2, static_cast<std::size_t>(m - 2), rep), node::FrameStatus::kOk);
  EXPECT_EQ(rep.k, 5u);
  EXPECT_EQ(rep.tau_us, 250000 - 210010);
  EXPECT_EQ(rep.y[1], -1.5);
  EXPECT_EQ(rep.u_applied[0], -0.25);
}

TEST(NcsLiveUdp, RunFileRoundTripsAndBadLogsAreRefused) {
  LiveRun r;
  r.dir = "x";
  r.approach = Approach::kAKl;
  r.scenario = default_scenarios()[3];
  r.seed = 17;
  r.t0_ns = 123456789;
  r.relay_port = 1;
  r.plant_port = 2;
  r.sensor_port = 3;
  r.controller_port = 4;
  r.actuator_port = 5;
  const LiveRun back = live_run_from_json(to_json(r), "test");
  EXPECT_EQ(to_json(back), to_json(r));
  nlohmann::json bad = to_json(r);
  bad["ports"]["relay"] = 0;
  EXPECT_THROW(live_run_from_json(bad, "test"), engine::InputError);
  const std::string dir = test::fresh_dir("ncs_live", "badlog");
  std::filesystem::create_directories(dir);
  std::ofstream(dir + "/plant.csv") << "event,t_ns,clock_us,src,dst,k,v0,v1,v2\nsample,12,x,0,0,1,0,0,0\n";
  EXPECT_THROW(read_log(dir, "plant"), engine::InputError);
  std::filesystem::remove_all(dir);
}

/// One short live run for every check below (each TEST is its own process under ctest).
TEST(NcsLive, ShortRunLogsAreConsistentAndItsReplayReproducesTheCost) {
  LiveOptions o;
  o.approach = Approach::kAK;
  o.scenario = default_scenarios()[1];  // d = 14 ms: the longest delays
  o.scenario.duration_s = 2;
  o.seed = 3;
  o.out_dir = test::fresh_dir("ncs_live", "run");
  o.executable = ONESHOT_SIM_PATH;
  const nlohmann::json j = run_live(o);
  const auto ctx = Context::load("");
  const std::int64_t h_ns = std::int64_t{ctx->period_us()} * 1000;

  // Every application of the plant is a command the actuator sent for the same period.
  std::map<std::uint32_t, double> commanded;
  for (const auto& r : read_log(o.out_dir, "actuator"))
    if (r.event == "command") commanded[r.k] = r.v[0];
  std::size_t applied = 0;
  for (const auto& r : read_log(o.out_dir, "plant")) {
    if (r.event != "apply") continue;
    ++applied;
    ASSERT_EQ(commanded.count(r.k), 1u) << "k " << r.k;
    EXPECT_EQ(commanded[r.k], r.v[0]);
    EXPECT_GE(r.t_ns, std::int64_t{r.k} * h_ns);  // never before its instant
  }
  EXPECT_GT(applied, 0u);
  EXPECT_EQ(j.at("actuation_instants_recorded").get<std::size_t>(), applied);

  // The relay held every frame for its link's model draw: the engine's Link with the run's
  // seed gives the same arrival for the same receipt instants, and nothing left early.
  std::map<int, std::unique_ptr<engine::Link>> links;
  const char* names[4] = {"", "sc", "ca", "as"};  // by source address
  for (int src : {1, 2, 3}) links[src] = std::make_unique<engine::Link>(leg(*ctx, o.scenario, o.approach, names[src]), o.seed);
  std::size_t in = 0, out = 0;
  for (const auto& r : read_log(o.out_dir, "relay")) {
    if (r.event == "in") {
      ++in;
      const auto arrival = links.at(r.src)->transmit(engine::SimTime{r.t_ns});
      ASSERT_TRUE(arrival.has_value());
      EXPECT_EQ(static_cast<double>(arrival->count() - r.t_ns), r.v[0]);
      EXPECT_GE(r.v[0], static_cast<double>(ctx->timing().leg_min_us) * 1000);
    } else if (r.event == "out") {
      ++out;
      EXPECT_GE(static_cast<double>(r.t_ns), r.v[1]);  // forwarded at or after its release
    }
  }
  EXPECT_GT(in, 0u);
  EXPECT_EQ(in, out);

  // The replay recomputes every command from the recorded instants, frames and noise: the
  // same commands and the same cost (measured: identical to the last bit; tolerance 1e-12).
  EXPECT_EQ(j.at("replay_missing_frames").get<unsigned>(), 0u);
  EXPECT_EQ(j.at("replay_max_abs_u_difference").get<double>(), 0.0);
  EXPECT_EQ(j.at("replay_applied").get<std::size_t>(), applied);
  const double live = j.at("live_cost").get<double>();
  EXPECT_GT(live, 0);
  EXPECT_NEAR(j.at("replay_over_live").get<double>(), 1.0, 1e-12);

  // The replay really uses the recorded draws: one changed measurement-noise draw moves it.
  // A sample from the middle of the run (the first may precede the nodes' start and be unused).
  std::string plant = test::read_file(o.out_dir + "/plant.csv");
  std::vector<std::size_t> rows;
  for (std::size_t p = plant.find("\nsample,"); p != std::string::npos; p = plant.find("\nsample,", p + 1)) rows.push_back(p);
  ASSERT_GE(rows.size(), 3u);
  const std::size_t pos = rows[rows.size() / 2];
  std::size_t field = pos + 1;
  for (int c = 0; c < 6; ++c) field = plant.find(',', field) + 1;  // v0 = n0
  plant.replace(field, plant.find(',', field) - field, "2.5");  // n0 = 2.5: a different draw
  std::ofstream(o.out_dir + "/plant.csv") << plant;
  const ReplayResult changed = replay_live(o.out_dir);
  EXPECT_GT(std::fabs(changed.cost / live - 1), 1e-9);
  EXPECT_GT(changed.max_abs_u_difference, 0.0);
  std::filesystem::remove_all(o.out_dir);
}

/// A 2 s live run of AK on scenario a0.2-T2-d14-s1 with seed `seed` and faults `inject`.
LiveOptions faulted_run(std::uint64_t seed, const char* dir, const char* inject) {
  LiveOptions o;
  o.approach = Approach::kAK;
  o.scenario = default_scenarios()[1];
  o.scenario.duration_s = 2;
  o.seed = seed;
  o.inject = inject;
  o.out_dir = test::fresh_dir("ncs_live", dir);
  o.executable = ONESHOT_SIM_PATH;
  return o;
}

/// The relay's fault draws again: LinkFaults with the run's seed fed the relay's receipt
/// instants per link (frames of each link's size), as the relay drew them.
struct RelayFaults {
  engine::FaultCounters total;           ///< Every frame's faults.
  std::size_t inject_records = 0;        ///< "inject" lines of the relay log.
  std::size_t nan_and_forged_frames = 0; ///< Frames both made NaN and given a forged k.
};

RelayFaults redraw_relay_faults(const LiveOptions& o) {
  const auto ctx = Context::load("");
  const engine::FaultSpec spec = engine::parse_fault_spec(o.inject);
  std::map<int, std::unique_ptr<engine::LinkFaults>> faults;
  const char* names[4] = {"", "sc", "ca", "as"};  // by source address
  const std::size_t sizes[4] = {0, node::report_size<double, kP, kM>(), node::encoded_size<double, kM>(),
                                node::request_size<double, kM>()};
  for (int src : {1, 2, 3}) {
    const engine::LinkConfig cfg = leg(*ctx, o.scenario, o.approach, names[src]);
    faults[src] = std::make_unique<engine::LinkFaults>(spec, cfg.name, cfg.frame, o.seed);
  }
  RelayFaults r;
  for (const auto& rec : read_log(o.out_dir, "relay")) {
    r.inject_records += rec.event == "inject" ? 1u : 0u;
    if (rec.event != "in") continue;
    std::vector<std::uint8_t> bytes(sizes[rec.src], 0);
    std::vector<std::vector<std::uint8_t>> extra;
    engine::LinkFaults& f = *faults.at(rec.src);
    const engine::FaultCounters before = f.counters();
    f.apply(engine::SimTime{rec.t_ns}, bytes, extra);
    if (f.counters().nan > before.nan && f.counters().forge_seq > before.forge_seq) ++r.nan_and_forged_frames;
  }
  for (const auto& [src, f] : faults) r.total += f->counters();
  return r;
}

/// A faulted live run: duplicates, bit flips, replays and restarts of two nodes. The run
/// completes, the relay's injected frames and the restarts are counted, and the replay
/// (recorded injected bytes, recorded restarts) gives the live cost again.
TEST(NcsLive, FaultedRunCompletesAndItsReplayReproducesIt) {
  const LiveOptions o = faulted_run(3, "faults",
                                    "dup:rate=0.1;flip:link=ca,rate=0.05;replay:link=sc,rate=0.1;"
                                    "restart:node=actuator,at_s=1;restart:node=controller,at_s=1.5");
  const nlohmann::json j = run_live(o);
  EXPECT_EQ(j.at("inject").get<std::string>(), o.inject);
  const auto& injected = j.at("faults_injected");
  EXPECT_GT(injected.at("dup").get<double>(), 0);
  EXPECT_GT(injected.at("replay").get<double>(), 0);
  const auto& counters = j.at("node_counters");
  EXPECT_EQ(counters.at("actuator.restarts").get<double>(), 1);
  EXPECT_EQ(counters.at("controller.restarts").get<double>(), 1);
  EXPECT_EQ(counters.at("sensor.restarts").get<double>(), 0);
  EXPECT_GT(counters.at("sensor.stale").get<double>(), 0);  // duplicated requests
  // The relay drew the engine's faults: LinkFaults with the run's seed, fed the relay's receipt
  // instants per link (frames of each link's size), injects the same counts.
  const RelayFaults redrawn = redraw_relay_faults(o);
  const engine::FaultCounters& total = redrawn.total;
  const std::size_t inject_records = redrawn.inject_records;
  EXPECT_EQ(static_cast<double>(total.dup), injected.at("dup").get<double>());
  EXPECT_EQ(static_cast<double>(total.flip), injected.at("flip").get<double>());
  EXPECT_EQ(static_cast<double>(total.replay), injected.at("replay").get<double>());
  EXPECT_EQ(static_cast<double>(total.skipped), injected.at("skipped").get<double>());
  EXPECT_GE(inject_records, static_cast<std::size_t>(injected.at("dup").get<double>()));
  EXPECT_TRUE(std::filesystem::exists(o.out_dir + "/injected.csv"));
  EXPECT_EQ(j.at("replay_missing_frames").get<unsigned>(), 0u);
  EXPECT_EQ(j.at("replay_max_abs_u_difference").get<double>(), 0.0);
  EXPECT_NEAR(j.at("replay_over_live").get<double>(), 1.0, 1e-12);
  EXPECT_TRUE(std::isfinite(j.at("simulated_cost").get<double>()));
  std::filesystem::remove_all(o.out_dir);
}

/// Issue 24's live symptoms: NaN frames on every link and forged sequence numbers on the
/// request and report links. Before the nodes refused them the run ended with "field
/// 'live_cost' is not a finite number" (NaN) or a loop that stopped commanding (forged k).
/// The run completes with a finite cost, every fault is refused and counted by the node it
/// reaches, commands keep coming, and the replay reproduces the live cost.
TEST(NcsLive, NanAndForgedSequenceFramesAreRefusedAndTheLoopGoesOn) {
  const LiveOptions o = faulted_run(4, "nan_forged",
                                    "nan:link=as,rate=0.05;nan:link=sc,rate=0.05;nan:link=ca,rate=0.05;"
                                    "forge_seq:link=as,at_s=0.5;forge_seq:link=sc,at_s=1");
  const nlohmann::json j = run_live(o);
  const double live = j.at("live_cost").get<double>();
  EXPECT_TRUE(std::isfinite(live));
  EXPECT_TRUE(std::isfinite(j.at("simulated_cost").get<double>()));
  const auto& injected = j.at("faults_injected");
  const auto& c = j.at("node_counters");
  const double refused_nan = c.at("sensor.refused_non_finite").get<double>() +
                             c.at("controller.refused_non_finite").get<double>() +
                             c.at("actuator.refused_non_finite").get<double>();
  EXPECT_GT(injected.at("nan").get<double>(), 0);
  EXPECT_EQ(refused_nan, injected.at("nan").get<double>());  // every NaN refused where it arrives
  EXPECT_EQ(injected.at("forge_seq").get<double>(), 2);
  EXPECT_EQ(c.at("controller.estimator_resets").get<double>(), 0);
  EXPECT_NEAR(j.at("replay_over_live").get<double>(), 1.0, 1e-12);
  // A forged frame that also drew a NaN is refused as not finite (the graver cause): which
  // frames the forges hit depends on the live timing, so the collisions are counted from the
  // relay's draws (seen once under ASan with two builds running).
  const RelayFaults redrawn = redraw_relay_faults(o);
  EXPECT_EQ(static_cast<double>(redrawn.total.nan), injected.at("nan").get<double>());
  const double forged_refused = c.at("sensor.refused_sequence").get<double>() + c.at("controller.refused_sequence").get<double>();
  const double reacquired = c.at("sensor.reacquired").get<double>() + c.at("controller.reacquired").get<double>();
  if (test::kSanitizedBuild) {
    // Under ASan on a loaded machine the processes fall behind (measured: 21 of 39 commands
    // late): a node then finds the frames after a forged one outside its window too and
    // re-acquires the peer instead of counting the forged frame.
    EXPECT_EQ(forged_refused + reacquired, 2.0 - static_cast<double>(redrawn.nan_and_forged_frames));
  } else {
    EXPECT_EQ(forged_refused, 2.0 - static_cast<double>(redrawn.nan_and_forged_frames));
  }
  // Commands go on: the loop stopped by a forged k commanded nothing after it. Commands after
  // the last forged frame (1 s) plus five periods: the live timing decides how many (measured
  // 6 to 21 of 39 late, release and ASan), never none.
  std::size_t commands_after = 0;
  for (const auto& r : read_log(o.out_dir, "actuator"))
    commands_after += r.event == "command" && r.t_ns > 1'250'000'000 ? 1u : 0u;
  EXPECT_GT(commands_after, 0u);
  std::filesystem::remove_all(o.out_dir);
}

}  // namespace
}  // namespace oneshot::ncs
