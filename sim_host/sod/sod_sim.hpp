/// @file sod_sim.hpp
/// @brief One run of the send-on-delta study on the engine: the sampled plant, two sensor
///        nodes with their trigger rule, one lossy link per node, the receiver and the
///        estimator (send-on-delta brief §2–§4).
///
/// Per step k (instant kT, after the plant step to x_k): node i samples y_i = x_i + v_i
/// (stream "measurement/<node>"), its rule decides, a packet goes over link "<node>"
/// (Bernoulli loss ξ drawn from the link's own stream, no delay), arrives as a kDelivery
/// event, and the estimator runs in kCompute: predict (k ≥ 1), then one scalar correction
/// per node with what the receiver gives. The senders' decisions depend only on the plant
/// and measurement streams, so plain SOD sends the same packets at every ξ for a seed.
///
/// With a fault spec (RunConfig::faults, frame faults on links "node1", "node2" only) each
/// packet travels as a frame [k: u32 LE][y: f64][crc: u16] (engine/sequenced_frame.hpp)
/// through the link's engine::LinkFaults before the loss draw; the receiver refuses a frame
/// whose CRC-16 does not match (corrupt: to the receiver a lost packet, which its detector
/// counts as one), then takes a frame only when its k is the current sample
/// (the links have no delay: another k is a replay or forged, refused_sequence) and its y is
/// finite (refused_non_finite). An empty spec is the clean run, bit for bit.
#pragma once

#include <cstdint>
#include <vector>

#include "oneshot/engine/fault_spec.hpp"
#include "oneshot/engine/frame_faults.hpp"
#include "sod_model.hpp"

namespace oneshot::sod {

/// The sender rule of both nodes.
enum class SenderKind : std::uint8_t {
  kSod,          ///< (2a) only.
  kModifiedSod,  ///< (2a) or (2b) after n_t samples.
  kPeriodic,     ///< Every `every`-th sample.
};

/// What the receiver does when a node is silent.
enum class FilterKind : std::uint8_t {
  kHeld,         ///< §4: the held value with R̄ (d from the detector; d ≡ 0 for plain SOD).
  kPredictOnly,  ///< A Kalman filter that only predicts when nothing arrives.
};

/// Everything that fixes one run besides the seed.
struct RunConfig {
  SenderKind sender = SenderKind::kSod;    ///< Rule.
  FilterKind filter = FilterKind::kHeld;   ///< Estimator.
  double delta_y[kNodes] = {0.5, 0.5};     ///< δy,i.
  std::uint32_t n_t[kNodes] = {0, 0};      ///< Modified SOD: round(δt,i/T) (0: no time rule).
  std::uint32_t every[kNodes] = {1, 1};    ///< Periodic: every n-th sample.
  double loss = 0;                         ///< ξ (both links).
  double amplitude = 1;                    ///< Step input u(t) = amplitude for t ≥ 0.
  std::int64_t steps = 5000;               ///< N (samples k = 0 … N).
  double tail_from_s = 20;                 ///< Start of the "slow tail" error window.
  double p0 = 0.01;                        ///< P(0) = p0·I, x̂(0) = x(0) = 0.
  bool noise = true;                       ///< Process and measurement noise (false: noise-free).
  engine::FaultSpec faults;                ///< Frame faults on links node1, node2 (empty: clean).
};

/// Figures of one run.
struct RunResult {
  double e[kNodes] = {};          ///< e_i = (1/N) Σ_{k=1..N} (x_k,i − x̂_k,i)².
  double e_tail[kNodes] = {};     ///< The same over t ≥ tail_from_s.
  double nees = 0;                ///< (1/N) Σ e_kᵀ P_k⁻¹ e_k (2 when consistent).
  double sends[kNodes] = {};      ///< Packets sent (lost ones included).
  double time_sends[kNodes] = {}; ///< Of which caused by (2b).
  double lost[kNodes] = {};       ///< Lost on the link.
  double detected[kNodes] = {};   ///< Losses the detector proved (Σ increments of d).
  double estimator_resets = 0;    ///< Steps whose estimate turned non-finite (reset to x0, P0).
  double corrupt = 0;             ///< Frames the receiver refused: CRC-16 mismatch (faults only).
  double refused_non_finite = 0;  ///< Frames the receiver refused: y not finite (faults only).
  double refused_sequence = 0;    ///< Frames the receiver refused: k not the current sample (faults only).
  engine::FaultCounters injected; ///< Faults injected on both links.
  double events = 0;              ///< Kernel events run (queue pops: plant steps, samples, deliveries, estimator steps).
};

/// The link names a fault spec of the study may name.
inline std::vector<std::string> sod_link_names() { return {"node1", "node2"}; }

/// Per-step record of a run (E4 and the tests).
struct RunTrace {
  std::vector<double> t_s;                  ///< kT.
  std::vector<double> x[kNodes];            ///< True state.
  std::vector<double> x_hat[kNodes];        ///< Corrected estimate.
  std::vector<double> p[kNodes];            ///< P_ii after the correction.
  std::vector<double> y[kNodes];            ///< Measurement y_i,k.
  std::vector<double> z[kNodes];            ///< Value the filter used (NaN: none).
  std::vector<double> r_bar[kNodes];        ///< Its variance (NaN: none).
  std::vector<std::uint8_t> cause[kNodes];  ///< node::SendCause of the sample.
  std::vector<std::uint8_t> arrived[kNodes];///< 1 when the packet arrived.
  std::vector<std::uint32_t> dropouts[kNodes];   ///< d_i at the step.
  std::vector<std::uint32_t> true_lost_run[kNodes];  ///< Packets sent since the last arrival, all lost.
};

/// Runs one configuration for `seed`; fills `trace` when given.
RunResult simulate_run(const SodModel& model, const RunConfig& cfg, std::uint64_t seed, RunTrace* trace = nullptr);

}  // namespace oneshot::sod
