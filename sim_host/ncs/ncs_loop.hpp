/// @file ncs_loop.hpp
/// @brief One run of study `ncs`: an approach on a scenario with a seed, on the engine.
///
/// Three firmware nodes (firmware/node/) on the engine's network, around the continuous
/// plant of the plant file (exact propagation and cost). Actuation-synchronized loops (A,
/// AK, AKx, AKl): the actuator's timer at t_k = kh applies command k and sends msg 1 over
/// link "as"; the sensor samples on arrival (AKl: at t_k − D) and reports over "sc"; the
/// controller computes τ_c later and sends over "ca". Baseline loops (I, S, SK, S+, IK):
/// the sensor samples at kh, the controller computes τ_c after arrival, the actuator applies
/// on arrival. Links: uniform delays U[0.5, d] ms in whole µs, or the legs a study file gives
/// (Scenario::legs: their delay, loss and order); τ_c ~ U[1, 5] ms (stream
/// "compute"); I and IK have none. Streams per source (common random numbers): process,
/// measurement, compute, link/<as|sc|ca>/delay. With a fault spec (RunOptions::faults)
/// Legs a study file puts on a CAN bus (Scenario::bus_legs) go over the engine's CanBus with
/// their identifier and the bus's background traffic (CanTraffic, stream "can/<bus>/jitter");
/// I and IK keep their delay-free links. With a fault spec (RunOptions::faults)
/// the links carry the engine's frame faults and the nodes "sensor", "controller",
/// "actuator" restart at the spec's instants: a restarted node is rebuilt as at power-on
/// (its interface emptied; the actuator's period index starts again from 0 at its next
/// timer, the plant keeping the last applied input until a new command is applied).
/// With clock offsets (Scenario::sensor_clock_us) each node's clock reads t − φ of its own: the
/// timer node's φ shifts the loop (t_k = kh + φ_a, samples at kh + φ_s), the others' against it
/// are what its nodes read on their clocks.
#pragma once

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "ncs_model.hpp"
#include "ncs_reference.hpp"
#include "oneshot/engine/continuous_plant.hpp"
#include "oneshot/engine/jump_linear_cost.hpp"
#include "oneshot/engine/fault_spec.hpp"
#include "oneshot/engine/frame_faults.hpp"
#include "oneshot/engine/link.hpp"
#include "oneshot/engine/network.hpp"

namespace oneshot::ncs {

class ShapeCachePools;  // ncs_cache_pools.hpp

/// Options of a run.
struct RunOptions {
  bool noise_free = false;  ///< No process or measurement noise (delays stay).
  double trace_step_s = 0;  ///< > 0: record the true state every step (bridged, never changes the run).
  engine::FaultSpec faults;  ///< Faults injected (empty: a clean run, bit-identical to none).
  /// Also the exact expected cost over the noise for this run's timing (ncs_analytic.hpp);
  /// the simulation itself then runs noise-free (same delays and τ_c: streams per source).
  bool analytic = false;
  /// ≠ 0: the process and measurement noise drawn from this seed, the timing still from the
  /// run's (a Monte Carlo over the noise alone for one timing draw).
  std::uint64_t noise_seed = 0;
  /// > 0 (analytic runs only, at or before the end: std::invalid_argument otherwise): also the
  /// expected cost at this instant (s) in RunResult::analytic_at_mark,
  /// as a run of this duration would end with it; the run itself is unchanged.
  double analytic_mark_s = 0;
  /// Log every message of the legs in RunResult::messages (observes only: the run is unchanged).
  bool record_messages = false;
  /// The plant's interval maps and noise terms from these caches shared by a sweep's runs,
  /// the pool of the plant's shape (ncs_cache_pools.hpp; nullptr: the run's own). The same
  /// run, bit for bit.
  ShapeCachePools* caches = nullptr;
  /// Tests: run the plant embedded in this shape of ONESHOT_NCS_SHAPES (n, m, p; it must hold
  /// the plant: std::invalid_argument otherwise) instead of ncs_shape_of()'s; {0, 0, 0}: that one.
  NcsShapeOf force_shape{};
};

/// One row of a recorded sample or estimate.
struct Point {
  double t_s = 0;    ///< Time (s).
  double v[2] = {};  ///< Values (y1, y2 or x̂1, x̂2).
};

/// The controller's CPU over a run (Scenario::controller_cpu): its job's response times (τ_c),
/// misses and the CPU's busy time.
struct CpuRunStats {
  bool present = false;           ///< The run's controller ran on a CPU.
  std::uint64_t jobs = 0;         ///< Controller jobs finished.
  engine::Duration response_min{0};  ///< Smallest response (finish − release).
  engine::Duration response_max{0};  ///< Largest.
  double response_sum_us = 0;     ///< Σ responses (µs).
  std::uint64_t deadline_misses = 0;  ///< Controller jobs past their deadline (or aborted).
  std::uint64_t other_misses = 0;     ///< Background tasks' and ISRs' misses.
  engine::Duration busy{0};       ///< CPU time used by every task and ISR (context switches included).
  engine::Duration sample_min{0};  ///< Smallest sample − release of the job (the sensor's).
  engine::Duration sample_max{0};  ///< Largest.
};

/// One message of a leg (RunOptions::record_messages), in the order sent.
struct MessageEvent {
  std::string leg;         ///< "as", "sc" or "ca".
  double sent_s = 0;       ///< Handed to the link (queued on the bus).
  double arrival_s = 0;    ///< Arrival when delivered (may lie after the run's end: in flight then).
  bool lost = false;       ///< Dropped by the leg's loss model.
  bool delivered = false;  ///< Not lost (a bus leg's: its last frame ended within the run).
};

/// What a run returns.
struct RunResult {
  double cost = 0;             ///< J over the run.
  std::uint32_t late = 0;      ///< Periods whose command was late (actuation-synchronized).
  std::uint32_t saturated = 0; ///< Commands clamped to the actuator's range.
  std::uint32_t faults = 0;    ///< Estimator runs whose status was not exact.
  std::uint32_t commands = 0;  ///< Commands applied.
  engine::FaultCounters injected;  ///< Faults injected.
  engine::ExpectedCost analytic;   ///< Analytic runs: E[J] over the noise, split by origin.
  engine::ExpectedCost analytic_at_mark;  ///< Analytic runs: E[J] up to RunOptions::analytic_mark_s (0 without).
  std::string analytic_refusal;    ///< Analytic runs: why the expected cost is not valid ("" when it is).
  double analytic_mismatch = 0;    ///< Analytic runs: largest |mean − simulated| (relative to max(1, |value|)).
  std::vector<double> counters;    ///< Node counters (ncs_counters.hpp, order of counter_names()).
  /// Loops whose controller runs a Kalman filter (filtered_approach()): the mean of
  /// e_kᵀ P_k⁻¹ e_k, e_k the true state minus the filter's estimate, P_k its covariance, over
  /// the computations whose P_k is regular (not at noise scale 0; 0 for the other loops and
  /// when none is). SK, IK and the one-shot loops: x(kh) (the sample's instant) against
  /// x̂_{k|k}, P_{k|k} after the corrections of period k; AK, AKx, AKl: x(t_k) against the
  /// prediction x̂⁻_k, P⁻_k to the actuation instant, over the periods whose command k is
  /// applied at t_k. Runs with injected faults: none.
  double nees = 0;
  std::uint32_t nees_steps = 0;    ///< Computations in that mean.
  std::uint32_t sent = 0;          ///< One-shot loops: samples the sensor sent (of `samples`).
  std::uint32_t sampled = 0;       ///< One-shot loops: samples the sensor took.
  /// Counters of the links the run built, by leg name (order of link_names()).
  std::vector<std::pair<std::string, engine::LinkStatistics>> links;
  /// Legs on a CAN bus (Scenario::bus_legs), by leg name: messages queued and their delays
  /// (queueing + transmission of every frame). Their sent counts are in `links` too (lost 0).
  std::vector<std::pair<std::string, engine::BusRouteStatistics>> bus_legs;
  CpuRunStats cpu;               ///< The controller's CPU (Scenario::controller_cpu; I, IK: none).
  CpuRunStats sensor_cpu;        ///< The sensor's CPU (Scenario::sensor_cpu; I, IK: none).
  std::vector<MessageEvent> messages;  ///< RunOptions::record_messages: every message of the legs.
  std::uint64_t events = 0;      ///< Kernel events run (the engine's event queue pops).
  std::vector<Point> truth;      ///< True state every trace step (x1, x2).
  std::vector<Point> samples;    ///< Samples y at their instants.
  std::vector<Point> sample_truth;  ///< C x at the same instants (noise-free output).
  std::vector<Point> estimates;  ///< Controller's x̂ at the instant it targets (t_k, or kh).
  std::vector<Point> setpoint;   ///< x_ref,1 and u at each trace step.
};

/// The plant of shape S of a run (process noise when `noisy`; S one of ONESHOT_NCS_SHAPES).
template <typename S>
engine::ContinuousPlantConfig<S::n, S::m, S::p, 1> plant_config_of(const Context& ctx, const Scenario& sc, bool noisy);
/// The board's plant of a run, shared by the simulation and the live plant.
inline engine::ContinuousPlantConfig<kN, kM, kP, 1> plant_config(const Context& ctx, const Scenario& sc, bool noisy) {
  return plant_config_of<BoardShape>(ctx, sc, noisy);
}
/// The set-point of a scenario for the plant of shape S (x_ref, u_ref = N_x r_k, N_u r_k per
/// period index, N_x, N_u the design's feed-forward of the tracked output): its steps
/// (Scenario::setpoint_changes) or the square wave ±A_r of period T_r.
template <typename S>
BasicSetpointReference<S::n, S::m> reference_of(const Context& ctx, const Scenario& sc);
/// reference_of() for the board's plant.
inline SetpointReference reference(const Context& ctx, const Scenario& sc) { return reference_of<BoardShape>(ctx, sc); }
/// Network leg `name` ("as", "sc", "ca"): U[0.5, d] ms in whole µs, FIFO, or the scenario's
/// leg from a study file (Scenario::legs); none for I, IK.
engine::LinkConfig leg(const Context& ctx, const Scenario& sc, Approach a, const char* name);
/// Lower Cholesky factor of R = s·R_n of the board: y = C x + [[c0, 0], [c1, c2]] n, n ~ N(0, I).
std::array<double, 3> measurement_cholesky(const Design& d);

/// Names of the node counters of approach `a` (RunResult::counters).
std::vector<std::string> counter_names(Approach a);
/// Names of the links ("as", "sc", "ca"; "sc", "ca" for the sampling loops) and of the
/// restartable nodes of approach `a`, for checking a fault spec.
std::vector<std::string> link_names(Approach a);
/// The restartable nodes: "sensor", "controller", "actuator".
std::vector<std::string> node_names();

/// Runs approach `a` on `scenario` with `seed` (with RunOptions::analytic, refused by
/// refuse_nonlinear_runs() when a command was clamped, late or an estimator run inexact).
RunResult run(const Context& ctx, Approach a, const Scenario& scenario, std::uint64_t seed, const RunOptions& options);

/// One loop of a run of several loops on one engine (their legs on the same CAN buses).
struct LoopOnBus {
  const Context* ctx = nullptr;        ///< Its plant and design.
  const Scenario* scenario = nullptr;  ///< Its scenario (legs, buses; the same duration in every loop).
  /// Prefixes its random streams: "<name>/process", "link/<name>/sc/…" (empty: no prefix, the
  /// streams of a loop run alone by run()).
  std::string name;
  std::uint8_t sensor = 0;             ///< Its sensor's address (unique in the run).
  std::uint8_t controller = 0;         ///< Its controller's.
  std::uint8_t actuator = 0;           ///< Its actuator's.
  /// The phase φ of its timer (its sensor's, I, S, SK, IK), whole µs, 0 ≤ φ < h: the loop
  /// runs on [φ, φ + duration] of the run's time, its samples at kh + φ, its set-point
  /// switches at kh + φ, its plant's time and cost from φ (the loop's own time shifted by φ;
  /// the plants are separate, so only the bus and its other traffic see the shift).
  std::int64_t clock_offset_us = 0;
};

/// Runs the sampling loop `a` (I, S, SK, IK; std::invalid_argument otherwise) of every loop
/// of `loops` together in one engine run with `seed` until the latest loop's end (its
/// clock_offset_us + duration; std::invalid_argument for an offset outside [0, h)): one
/// kernel, one network, their bus legs
/// on the same buses (arbitration by identifier with each other and the background traffic,
/// stream "can/<bus>/jitter"), each loop's streams named per loop. One result per loop, in order.
/// With `caches` each loop's plant takes its interval maps and noise terms from the pool of
/// its shape (RunOptions::caches: the same bytes as without).
std::vector<RunResult> run_loops(const std::vector<LoopOnBus>& loops, Approach a, std::uint64_t seed,
                                 ShapeCachePools* caches = nullptr);

/// The run without the analytic post-checks.
RunResult run_approach(const Context& ctx, Approach a, const Scenario& scenario, std::uint64_t seed, const RunOptions& options);

}  // namespace oneshot::ncs
