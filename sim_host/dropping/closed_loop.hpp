/// @file closed_loop.hpp
/// @brief One run of the dropping study on the engine: the discrete plant, the sensor
///        stamping y_j, the network (Poisson delay in whole periods + Bernoulli loss, any
///        order) or a Bernoulli(λ) channel, and the estimator + controller at every step.
///
/// Instant kT, in the engine's order: the plant steps to x_k (kPlantStep); the sensor
/// sends y_k = C x_k + v_k stamped k (kSample) — the link delivers it at kT + T/2 + τT,
/// τ ~ Poisson(D), so inside period (k+τ, k+τ+1] — ; the arrivals of the period
/// (kDelivery) enter the buffer; the estimator runs step k and the controller applies
/// u_k = −L x̂(k|Y_k) + r_k (kCompute), which the plant latches for step k (kLatch).
/// r_k: ±1 square wave, 4 s period. x₀ ~ N(0, P₀), x̂₀ = 0.
///
/// With a fault spec (RunConfig::faults; docs/faults.md, "Study dropping") each sample
/// travels as a frame [j: u32][y: f64][crc: u16] (engine/sequenced_frame.hpp) through the link
/// "sensor"'s engine::LinkFaults before the link's delay and loss draws (or the Bernoulli
/// channel's draw); the controller decodes it, refuses a frame whose CRC-16 does not match
/// (corrupt: a flipped bit; the sample is lost, as a lost packet), then a non-finite y
/// (refused_non_finite) and a stamp not yet sampled, j > the period it arrives in
/// (refused_sequence: a forged or corrupted stamp), before the threshold buffer (which drops
/// over-delayed stamps and duplicates) or the delay-unaware KF (which takes only a stamp
/// newer than the period's newest; older ones are `stale`). Node restarts are refused (no
/// restartable node: the sensor's stamps are the synchronized step index, the buffered
/// filter's step count cannot be re-based). An empty spec is the clean run, bit for bit.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "dropping_plant.hpp"
#include "oneshot/engine/fault_spec.hpp"
#include "oneshot/engine/frame_faults.hpp"
#include "oneshot/engine/link.hpp"

namespace oneshot::dropping {

/// The estimator of a run.
enum class EstimatorKind : std::uint8_t {
  kBuffered,  ///< Threshold buffer + anchor + re-run (brief §4).
  kUnaware,   ///< Delay-unaware KF: newest packet arrived this period taken as y_k (E5).
};

/// How measurements reach the estimator.
enum class ChannelKind : std::uint8_t {
  kNetwork,    ///< The engine's link: Poisson(D) whole periods, Bernoulli loss.
  kBernoulli,  ///< γ_k ~ Bernoulli(λ) directly, arrival half a period later (E4 check).
};

/// One run's settings.
struct RunConfig {
  EstimatorKind estimator = EstimatorKind::kBuffered;  ///< The estimator closing the loop.
  ChannelKind channel = ChannelKind::kNetwork;          ///< How measurements reach it.
  int t_hold = 1;                      ///< Buffer length T_hold (1 … 8).
  double mean_delay_periods = 1;       ///< D.
  double loss = 0.01;                  ///< ε.
  double bernoulli_lambda = 0.5;       ///< λ of the Bernoulli channel.
  double unaware_r = 2.5;              ///< R the delay-unaware KF assumes.
  std::size_t steps = 1000;            ///< Steps simulated.
  double square_wave_period_s = 4;     ///< Period of r_k (half of it a whole number of steps).
  double square_wave_amplitude = 1;    ///< r_k = ±this.
  /// The network's delay and loss models and order (a study file's link; run under the name
  /// "sensor", its streams link/sensor/delay|loss); unset: Poisson(D) whole periods + T/2,
  /// Bernoulli(ε), any order (mean_delay_periods, loss).
  std::optional<engine::LinkConfig> link;
  bool trace = false;                  ///< Keep per-step traces.
  engine::FaultSpec faults;            ///< Frame faults on link "sensor" (empty: clean run).
};

/// Per-step trace of a run (when RunConfig::trace).
struct RunTrace {
  std::vector<double> y;         ///< y_k = C x_k + v_k.
  std::vector<double> cx;        ///< C x_k (noise-free).
  std::vector<double> cxhat;     ///< C x̂(k|Y_k).
  std::vector<double> trace_p;   ///< tr P_k.
  std::vector<double> err;       ///< |x_k − x̂(k|Y_k)|².
  std::vector<double> u;         ///< u_k = −L x̂(k|Y_k) + r_k, the input applied for step k.
  std::vector<double> r;         ///< r_k, the square wave's value at step k.
};

/// What a run measures (time averages over the steps).
struct RunMetrics {
  double trace_p = 0;          ///< mean_k tr P_k (the estimator's covariance of x̂(k|Y_k)).
  double trace_p_anchor = 0;   ///< mean_n tr P(n|n) (buffered only; NaN otherwise).
  double err = 0;              ///< mean_k |x_k − x̂(k|Y_k)|².
  double err_anchor = 0;       ///< mean_n |x_n − x̂(n|n)|² (buffered only; NaN otherwise).
  double err_shadow_small_r = 0;    ///< mean_k |x_k − x̂_unaware(k)|², unaware KF with R = 0.05 run beside the buffered loop.
  double err_shadow_nominal_r = 0;  ///< The same with R = 2.5 (NaN unless the buffered filter closes the loop).
  double gamma = 0;            ///< Fraction of anchor steps with γ_n = 1 (buffered only).
  double cost = 0;             ///< Plant cost per step (xᵀQ1x + uᵀQ2u).
  double corrections = 0;      ///< Corrections per step.
  double over_delayed = 0;     ///< Packets dropped as over-delayed.
  double duplicates = 0;       ///< Duplicate packets ignored.
  double reordered = 0;        ///< Packets the link delivered out of order.
  bool failed = false;         ///< An estimator step reported a failure (innovation variance).
  double corrupt = 0;             ///< Frames refused by the controller: CRC-16 mismatch (faults only).
  double refused_non_finite = 0;  ///< Frames refused by the controller: y not finite (faults only).
  double refused_sequence = 0;    ///< Frames refused: stamp j after the arrival's period (faults only).
  double stale = 0;               ///< Frames not newer than the period's newest (what the unaware KF drops).
  double sent = 0;                ///< Samples sent (the link's, or the Bernoulli channel's draws).
  double lost = 0;                ///< Of them lost (the link's loss, or γ_k = 0; clean runs).
  double estimate_non_finite = 0; ///< Steps whose loop estimate x̂(k|Y_k) was not finite (faults only).
  engine::FaultCounters injected; ///< Faults injected on the link.
  double events = 0;              ///< Kernel events run (the engine's event queue pops: samples, computations, deliveries).
  RunTrace trace;              ///< Traces (when asked).
};

/// Runs one closed loop with `seed`; std::invalid_argument for T_hold outside 1 … 8.
RunMetrics run_closed_loop(const DroppingPlant& plant, const RunConfig& cfg, std::uint64_t seed);

/// The link names a fault spec of the study may name ("sensor").
inline std::vector<std::string> dropping_link_names() { return {"sensor"}; }

/// Checks a spec against the study: links as dropping_link_names(); a restart clause is an
/// engine::InputError naming the node (the study has no restartable node).
void check_dropping_faults(const engine::FaultSpec& spec);

/// γ frequency of the pipeline alone (network + ThresholdBuffer, no plant): the fraction of
/// stamps n = 0 … steps − 1 − T_hold found in the buffer at step n + T_hold.
double simulate_gamma_frequency(int t_hold, double mean_delay_periods, double loss, std::size_t steps,
                                std::uint64_t seed);

}  // namespace oneshot::dropping
