/// @file ncs_live.cpp
/// @brief Live runs of study `ncs`: run file, logs, the process launcher, the analysis
///        beside the replay, and the commands `ncs live`, `ncs replay`, `ncs node` (hidden).
#include "ncs_live.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <memory>
#include <set>
#include <sstream>

#include "ncs_live_nodes.hpp"
#include "ncs_loop.hpp"
#include "oneshot/engine/quantiles.hpp"
#include "oneshot/util/child_process.hpp"
#include "oneshot/posix/udp_network.hpp"
#include "oneshot/sim/cli_commands.hpp"
#include "oneshot/util/output_files.hpp"

namespace oneshot::ncs {

nlohmann::json to_json(const LiveRun& r) {
  const Scenario& s = r.scenario;
  return {{"dir", r.dir},
          {"plant_file", r.plant_file},
          {"approach", name(r.approach)},
          {"scenario",
           {{"name", s.name},
            {"amplitude_volts", s.amplitude_volts},
            {"period_s", s.period_s},
            {"max_delay_ms", s.max_delay_ms},
            {"noise_scale", s.noise_scale},
            {"duration_s", s.duration_s}}},
          {"seed", r.seed},
          {"noise_free", r.noise_free},
          {"inject", r.inject},
          {"t0_ns", r.t0_ns},
          {"ports",
           {{"relay", r.relay_port},
            {"plant", r.plant_port},
            {"sensor", r.sensor_port},
            {"controller", r.controller_port},
            {"actuator", r.actuator_port}}}};
}

LiveRun live_run_from_json(const nlohmann::json& j, const std::string& source) {
  using engine::InputError;
  try {
    engine::require_keys(j, "run",
                         {"dir", "plant_file", "approach", "scenario", "seed", "noise_free", "inject", "t0_ns", "ports"});
    LiveRun r;
    r.dir = engine::string_of(j, "run", "dir");
    const nlohmann::json& pf = engine::member(j, "run", "plant_file");
    if (!pf.is_string()) throw InputError("field 'run.plant_file': must be a string (empty: the built-in plant)");
    r.plant_file = pf.get<std::string>();
    r.approach = parse_approach(engine::string_of(j, "run", "approach"));
    const nlohmann::json scen = {{"description", "live"}, {"scenarios", nlohmann::json::array({engine::member(j, "run", "scenario")})}};
    r.scenario = parse_scenarios(scen.dump(), source).at(0);
    r.seed = static_cast<std::uint64_t>(engine::integer_in(j, "run", "seed", 0, std::int64_t{1} << 62));
    r.noise_free = engine::boolean_of(j, "run", "noise_free", false);
    if (j.contains("inject")) {
      if (!j.at("inject").is_string()) throw InputError("field 'run.inject': must be a string (empty: no faults)");
      r.inject = j.at("inject").get<std::string>();
    }
    engine::check_fault_targets(engine::parse_fault_spec(r.inject), link_names(r.approach), node_names());
    r.t0_ns = engine::integer_in(j, "run", "t0_ns", 0, std::int64_t{1} << 62);
    const nlohmann::json& p = engine::member(j, "run", "ports");
    engine::require_keys(p, "ports", {"relay", "plant", "sensor", "controller", "actuator"});
    const auto port = [&](const char* k) { return static_cast<std::uint16_t>(engine::integer_in(p, "ports", k, 1, 65535)); };
    r.relay_port = port("relay");
    r.plant_port = port("plant");
    r.sensor_port = port("sensor");
    r.controller_port = port("controller");
    r.actuator_port = port("actuator");
    return r;
  } catch (const std::invalid_argument& e) {
    throw InputError(source + ": " + e.what());
  }
}

LiveRun load_live_run(const std::string& dir) {
  const std::string path = dir + "/run.json";
  std::ifstream in(path);
  if (!in) throw engine::InputError(path + ": cannot read the live run file");
  std::ostringstream text;
  text << in.rdbuf();
  LiveRun r = live_run_from_json(engine::parse_json_strict(text.str(), path), path);
  r.dir = dir;  // the folder may have moved since the run
  return r;
}

std::vector<LogRecord> read_log(const std::string& dir, const std::string& role) {
  const std::string path = dir + "/" + role + ".csv";
  std::ifstream in(path);
  if (!in) throw engine::InputError(path + ": cannot read the log");
  std::vector<LogRecord> out;
  std::string line;
  std::getline(in, line);
  if (line != "event,t_ns,clock_us,src,dst,k,v0,v1,v2") throw engine::InputError(path + ": not a live log (header)");
  for (std::size_t no = 2; std::getline(in, line); ++no) {
    LogRecord r;
    char ev[32] = {};
    long long t = 0;
    unsigned clk = 0, k = 0;
    int n = 0;
    if (std::sscanf(line.c_str(), "%31[^,],%lld,%u,%d,%d,%u,%lf,%lf,%lf%n", ev, &t, &clk, &r.src, &r.dst, &k, &r.v[0], &r.v[1],
                    &r.v[2], &n) != 9 ||
        static_cast<std::size_t>(n) != line.size()) {
      throw engine::InputError(path + ":" + std::to_string(no) + ": malformed record");
    }
    r.event = ev;
    r.t_ns = t;
    r.clock_us = clk;
    r.k = k;
    out.push_back(r);
  }
  return out;
}

namespace {

nlohmann::json quantiles_us(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  if (v.empty()) return nullptr;
  return {{"p50", engine::sorted_quantile(v, 0.5)}, {"p99", engine::sorted_quantile(v, 0.99)}, {"max", v.back()},
          {"min", v.front()}, {"count", v.size()}};
}

/// A descriptor ≥ 10 (so that placing children's 3 and 4 never overwrites a source).
int high_fd(int fd) {
  const int h = ::fcntl(fd, F_DUPFD_CLOEXEC, 10);
  if (h < 0) throw std::runtime_error("fcntl F_DUPFD_CLOEXEC failed");
  ::close(fd);
  return h;
}

}  // namespace

nlohmann::json analyse_live(const std::string& dir) {
  const LiveRun run = load_live_run(dir);
  const auto ctx = Context::load_board(run.plant_file);
  const std::int64_t h_ns = std::int64_t{ctx->period_us()} * 1000;
  const std::int64_t end = engine::from_seconds(run.scenario.duration_s, "live duration").count();
  const auto plant = read_log(dir, "plant");
  const auto act = read_log(dir, "actuator");
  const auto sensor = read_log(dir, "sensor");
  const auto relay = read_log(dir, "relay");
  // Actuation instants: timer n ≥ 1 with n h < end applies command n.
  std::uint32_t expected = 0;
  for (std::int64_t n = 1; n * h_ns < end; ++n) ++expected;
  std::set<std::uint32_t> applied;
  std::vector<double> act_err, timer_err, stamp_err;
  double live_cost = std::nan("");
  for (const auto& r : plant) {
    if (r.event == "apply" && r.k >= 1 && r.k <= expected) {
      applied.insert(r.k);
      act_err.push_back(static_cast<double>(r.t_ns - std::int64_t{r.k} * h_ns) * 1e-3);
    } else if (r.event == "sample") {
      // The sensor stamps t_s with its clock when it asks; the plant samples when it reads.
      stamp_err.push_back(static_cast<double>(r.t_ns) * 1e-3 - static_cast<double>(r.clock_us));
    } else if (r.event == "end") {
      live_cost = r.v[0];
    }
  }
  std::uint32_t late = 0;
  for (const auto& r : act) {
    if (r.event == "timer") timer_err.push_back(static_cast<double>(r.t_ns - std::int64_t{r.k} * h_ns) * 1e-3);
    if (r.event == "stats") late = static_cast<std::uint32_t>(r.v[0]);
  }
  std::map<std::string, std::vector<double>> model_ms, realized_ms;
  const auto link_name = [](int src) { return src == kLiveActuator ? "as" : src == kLiveSensor ? "sc" : "ca"; };
  for (const auto& r : relay) {
    if (r.event != "out") continue;
    model_ms[link_name(r.src)].push_back(r.v[0] * 1e-6);
    realized_ms[link_name(r.src)].push_back(static_cast<double>(r.t_ns - static_cast<std::int64_t>(r.v[2])) * 1e-6);
  }
  nlohmann::json links = nlohmann::json::object();
  for (const auto& [l, v] : model_ms) {
    double mean = 0, lag = 0;
    for (std::size_t i = 0; i < v.size(); ++i) {
      mean += v[i];
      lag = std::max(lag, realized_ms[l][i] - v[i]);
    }
    links[l] = {{"frames", v.size()}, {"model_delay_mean_ms", mean / static_cast<double>(v.size())},
                {"max_forwarding_lag_ms", lag}};
  }
  const ReplayResult rep = replay_live(dir);
  const ReplayResult ideal = replay_live(dir, true);
  nlohmann::json j;
  j["experiment"] = "live";
  j["approach"] = name(run.approach);
  j["scenario"] = run.scenario.name;
  j["scenario_description"] = describe(run.scenario);
  j["seed"] = run.seed;
  j["noise_free"] = run.noise_free;
  j["actuation_instants_expected"] = expected;
  j["actuation_instants_recorded"] = applied.size();
  j["fraction_recorded"] = expected == 0 ? 0.0 : static_cast<double>(applied.size()) / expected;
  j["late_commands"] = late;
  j["actuation_error_us"] = quantiles_us(act_err);
  j["timer_error_us"] = quantiles_us(timer_err);
  j["sample_stamp_error_us"] = quantiles_us(stamp_err);
  j["links"] = links;
  j["live_cost"] = live_cost;
  j["replay_cost"] = rep.cost;
  j["replay_over_live"] = rep.cost / live_cost;
  j["replay_applied"] = rep.applied;
  j["replay_late"] = rep.late;
  j["replay_missing_frames"] = rep.missing_frames;
  j["replay_max_abs_u_difference"] = rep.max_abs_u_difference;
  j["ideal_instants_cost"] = ideal.cost;
  j["live_over_ideal_instants"] = live_cost / ideal.cost;
  j["ideal_instants_late"] = ideal.late;
  j["inject"] = run.inject;
  j["node_counters"] = nlohmann::json::object();
  for (const char* role : {"sensor", "controller", "actuator", "relay"}) {
    std::ifstream in(dir + "/counters_" + role + ".json");
    if (!in) continue;
    std::ostringstream text;
    text << in.rdbuf();
    const nlohmann::json c = engine::parse_json_strict(text.str(), dir + "/counters_" + role + ".json");
    for (const auto& [k, v] : c.items()) j[std::string(role) == "relay" ? "faults_injected" : "node_counters"][k] = v;
  }
  RunOptions sim_options;
  sim_options.noise_free = run.noise_free;
  sim_options.faults = engine::parse_fault_spec(run.inject);
  // The engine alone, same seed and faults.
  j["simulated_cost"] = ncs::run(*ctx, run.approach, run.scenario, run.seed, sim_options).cost;
  return j;
}

nlohmann::json run_live(const LiveOptions& o) {
  const auto ctx = Context::load_board(o.plant_file);
  if (!actuation_synchronized(o.approach)) {
    throw std::invalid_argument(std::string("ncs live: approach ") + name(o.approach) + " is not actuation-synchronized (A, AK, AKx, AKl)");
  }
  (void)half_wave_periods(*ctx, o.scenario);
  engine::check_fault_targets(engine::parse_fault_spec(o.inject), link_names(o.approach), node_names());
  util::make_directory(o.out_dir);
  for (const char* role : {"plant", "sensor", "controller", "actuator", "relay"}) {
    std::filesystem::remove(std::filesystem::path(o.out_dir) / (std::string(role) + ".csv"));
    std::filesystem::remove(std::filesystem::path(o.out_dir) / ("counters_" + std::string(role) + ".json"));
  }
  std::filesystem::remove(std::filesystem::path(o.out_dir) / "injected.csv");
  LiveRun r;
  r.dir = o.out_dir;
  r.plant_file = o.plant_file;
  r.approach = o.approach;
  r.scenario = o.scenario;
  r.seed = o.seed;
  r.noise_free = o.noise_free;
  r.inject = o.inject;
  struct Sock {
    int fd;
    ~Sock() { if (fd >= 0) ::close(fd); }
  };
  Sock relay{high_fd(posix::open_loopback_socket())}, plant{high_fd(posix::open_loopback_socket())},
      sensor{high_fd(posix::open_loopback_socket())}, controller{high_fd(posix::open_loopback_socket())},
      actuator{high_fd(posix::open_loopback_socket())}, sensor_io{high_fd(posix::open_loopback_socket())},
      actuator_io{high_fd(posix::open_loopback_socket())};
  r.relay_port = posix::bound_port(relay.fd);
  r.plant_port = posix::bound_port(plant.fd);
  r.sensor_port = posix::bound_port(sensor.fd);
  r.controller_port = posix::bound_port(controller.fd);
  r.actuator_port = posix::bound_port(actuator.fd);
  r.t0_ns = posix::monotonic_ns() + o.startup_ms * 1'000'000;
  util::write_json(o.out_dir + "/run.json", to_json(r));
  struct Role {
    const char* name;
    int net, io;
  };
  const Role roles[5] = {{"plant", plant.fd, -1}, {"relay", relay.fd, -1}, {"controller", controller.fd, -1},
                         {"sensor", sensor.fd, sensor_io.fd}, {"actuator", actuator.fd, actuator_io.fd}};
  std::vector<std::unique_ptr<util::ChildProcess>> children;
  for (const Role& role : roles) {
    util::ProcessSpec spec;
    spec.argv = {o.executable, "ncs", "node", "--role", role.name, "--run", o.out_dir, "--net-fd", "3"};
    spec.extra_fds.emplace_back(role.net, 3);
    if (role.io >= 0) {
      spec.argv.insert(spec.argv.end(), {"--io-fd", "4"});
      spec.extra_fds.emplace_back(role.io, 4);
    }
    children.push_back(std::make_unique<util::ChildProcess>(spec));
  }
  // Every process ends on its own shortly after the end. A process that fails stops the run
  // at once; one still running long after the end (10 s: slow sanitizer builds) is ended.
  const std::int64_t end_at = r.t0_ns + engine::from_seconds(o.scenario.duration_s, "live duration").count();
  std::string failures;
  std::vector<bool> ended(children.size(), false);
  for (std::size_t left = children.size(); left > 0 && failures.empty();) {
    for (std::size_t i = 0; i < children.size(); ++i) {
      if (ended[i] || !children[i]->wait_for(20)) continue;
      ended[i] = true;
      --left;
      const util::ExitStatus s = children[i]->wait();
      if (!s.success()) failures += std::string(" ") + roles[i].name + ": " + s.describe() + ";";
    }
    if (left > 0 && posix::monotonic_ns() > end_at + 10'000'000'000) {
      for (std::size_t i = 0; i < children.size(); ++i)
        if (!ended[i]) failures += std::string(" ") + roles[i].name + ": still running 10 s after the end;";
    }
  }
  for (auto& c : children) c->terminate(2000);  // no-op for the ended ones
  if (!failures.empty()) throw std::runtime_error("ncs live: a process failed:" + failures);
  nlohmann::json j = analyse_live(o.out_dir);
  util::write_json(o.out_dir + "/summary.json", j);
  return j;
}

}  // namespace oneshot::ncs

namespace oneshot::sim {
namespace {

void print_summary(const nlohmann::json& j) {
  const auto q = [&](const char* key) {
    const auto& v = j.at(key);
    if (v.is_null()) return std::string("n/a");
    char b[96];
    std::snprintf(b, sizeof b, "p50 %.1f us, p99 %.1f us, max %.1f us", v.at("p50").get<double>(), v.at("p99").get<double>(),
                  v.at("max").get<double>());
    return std::string(b);
  };
  std::printf("ncs live %s on %s, seed %llu\n", j.at("approach").get<std::string>().c_str(),
              j.at("scenario_description").get<std::string>().c_str(), j.at("seed").get<unsigned long long>());
  std::printf("actuation instants recorded: %zu / %zu (%.4f), late commands %u\n",
              j.at("actuation_instants_recorded").get<std::size_t>(), j.at("actuation_instants_expected").get<std::size_t>(),
              j.at("fraction_recorded").get<double>(), j.at("late_commands").get<unsigned>());
  std::printf("actuation-instant error (plant applies - t_k): %s\n", q("actuation_error_us").c_str());
  std::printf("timer wake-up error (actuator - t_k):          %s\n", q("timer_error_us").c_str());
  std::printf("sample stamp error (plant samples - t_s):      %s\n", q("sample_stamp_error_us").c_str());
  std::printf("cost: live %.9g, replay %.9g, replay/live %.9f (max |u_replay - u_live| %.3g, missing frames %u)\n",
              j.at("live_cost").get<double>(), j.at("replay_cost").get<double>(), j.at("replay_over_live").get<double>(),
              j.at("replay_max_abs_u_difference").get<double>(), j.at("replay_missing_frames").get<unsigned>());
  std::printf("same draws at ideal instants (actuation at t_k, samples at t_s): cost %.9g, live/ideal %.6f (late %u)\n",
              j.at("ideal_instants_cost").get<double>(), j.at("live_over_ideal_instants").get<double>(),
              j.at("ideal_instants_late").get<unsigned>());
  std::printf("the engine alone (same approach, scenario, seed, duration, faults): cost %.9g\n", j.at("simulated_cost").get<double>());
  if (!j.value("inject", std::string()).empty()) {
    std::printf("faults injected (%s): %s\nnode counters: %s\n", j.at("inject").get<std::string>().c_str(),
                j.value("faults_injected", nlohmann::json::object()).dump().c_str(), j.at("node_counters").dump().c_str());
  }
}

std::string self_executable() {
  std::error_code ec;
  const auto p = std::filesystem::read_symlink("/proc/self/exe", ec);
  if (ec) throw std::runtime_error("ncs live: cannot find this program (/proc/self/exe)");
  return p.string();
}

}  // namespace

void add_ncs_live_commands(CLI::App* study) {
  {
    auto o = std::make_shared<ncs::LiveOptions>();
    auto approach = std::make_shared<std::string>("AK");
    auto scenario = std::make_shared<std::string>("a0.2-T2-d14-s1");
    auto scenario_file = std::make_shared<std::string>();
    auto duration = std::make_shared<double>(30);
    auto json = std::make_shared<std::string>();
    o->out_dir = "out/ncs-live";
    CLI::App* cmd = study->add_subcommand(
        "live", "The loop as five processes over UDP loopback (plant, sensor, controller, actuator, delay relay), "
                "logged, then replayed on the engine");
    cmd->add_option("--approach", *approach, "A, AK, AKx or AKl")->capture_default_str();
    cmd->add_option("--scenario", *scenario, "scenario name")->capture_default_str();
    cmd->add_option("--scenarios", *scenario_file, "scenario file (default: the ten of the brief)")->check(CLI::ExistingFile);
    cmd->add_option("--duration", *duration, "seconds of real time")->check(CLI::Range(0.5, 3600.0))->capture_default_str();
    cmd->add_option("--seed", o->seed, "seed of the delay, noise and computation streams")->capture_default_str();
    cmd->add_option("--plant", o->plant_file, "plant file (default: lut_gen/plants/networked_board.json)")->check(CLI::ExistingFile);
    cmd->add_flag("--noise-free", o->noise_free, "no process or measurement noise");
    cmd->add_option("--inject", o->inject, "faults, e.g. 'dup:link=sc,rate=0.05;restart:node=actuator,at_s=2' (docs/faults.md)");
    cmd->add_option("--out", o->out_dir, "output directory (logs, run.json, summary.json)")->capture_default_str();
    cmd->add_option("--json", *json, "write the summary as JSON to PATH, or '-' for standard output");
    cmd->callback([o, approach, scenario, scenario_file, duration, json]() {
      o->approach = ncs::parse_approach(*approach);
      const auto list = scenario_file->empty() ? ncs::default_scenarios() : ncs::load_scenarios(*scenario_file);
      std::string names;
      bool found = false;
      for (const auto& s : list) {
        names += " " + s.name;
        if (s.name == *scenario) {
          o->scenario = s;
          found = true;
        }
      }
      if (!found) throw std::invalid_argument("ncs live: unknown scenario '" + *scenario + "' (" + names + " )");
      o->scenario.duration_s = *duration;
      o->executable = self_executable();
      const nlohmann::json j = ncs::run_live(*o);
      if (*json != "-") print_summary(j);
      if (!json->empty()) util::write_json(*json, j);
    });
  }
  {
    auto dir = std::make_shared<std::string>();
    auto json = std::make_shared<std::string>();
    CLI::App* cmd = study->add_subcommand("replay", "Replays the logs of `ncs live` on the engine and prints both costs");
    cmd->add_option("--log", *dir, "folder of a live run (its --out)")->required()->check(CLI::ExistingDirectory);
    cmd->add_option("--json", *json, "write the summary as JSON to PATH, or '-' for standard output");
    cmd->callback([dir, json]() {
      const nlohmann::json j = ncs::analyse_live(*dir);
      if (*json != "-") print_summary(j);
      if (!json->empty()) util::write_json(*json, j);
    });
  }
  {
    auto role = std::make_shared<std::string>();
    auto dir = std::make_shared<std::string>();
    auto net_fd = std::make_shared<int>(-1);
    auto io_fd = std::make_shared<int>(-1);
    CLI::App* cmd = study->add_subcommand("node", "one process of `ncs live` (internal)");
    cmd->group("");  // hidden
    cmd->add_option("--role", *role, "plant, sensor, controller, actuator, relay")->required();
    cmd->add_option("--run", *dir, "folder holding run.json")->required();
    cmd->add_option("--net-fd", *net_fd, "network socket descriptor")->required();
    cmd->add_option("--io-fd", *io_fd, "plant-link socket descriptor");
    cmd->callback([role, dir, net_fd, io_fd]() {
      const int code = ncs::run_live_role(*role, ncs::load_live_run(*dir), *net_fd, *io_fd);
      if (code != 0) throw std::runtime_error("ncs node " + *role + ": exit code " + std::to_string(code));
    });
  }
}

}  // namespace oneshot::sim
