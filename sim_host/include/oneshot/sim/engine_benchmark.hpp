/// @file engine_benchmark.hpp
/// @brief Throughput of the engine on a networked loop (a benchmark for the docs, not a
///        test): events per wall second and the real-time factor.
#pragma once

#include <nlohmann/json.hpp>

namespace oneshot::sim {

/// Runs the reference networked loop for `simulated_s` seconds on one core: the board's
/// double integrator (continuous, exact, with noise), a time-triggered sensor, a controller
/// and an actuator on arrival (firmware nodes over the host port), a uniform-delay lossy
/// sensor link and a 500 kbit/s CAN bus carrying the commands among six background streams.
/// Returns {"events", "wall_time_s", "events_per_second", "real_time_factor", …}.
nlohmann::json networked_loop_benchmark(double simulated_s, std::uint64_t seed);

}  // namespace oneshot::sim
