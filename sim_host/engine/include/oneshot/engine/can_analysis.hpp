/// @file can_analysis.hpp
/// @brief Worst-case response times of periodic CAN message streams: the revised analysis
///        of Davis, Burns, Bril & Lukkien, "Controller Area Network (CAN) schedulability
///        analysis: Refuted, revisited and revised", Real-Time Systems 35(3):239–272, 2007.
///
/// Stream m: identifier (priority; lower is higher), period T_m, queuing jitter J_m,
/// deadline D_m, transmission time C_m (can_bus.hpp, worst-case stuffing). hp(m): streams
/// of higher priority, lp(m): lower, hep(m) = hp(m) ∪ {m}.
///     B_m = max_{k ∈ lp(m)} C_k                                 (blocking: one lower frame
///                                                                 already on the bus)
///     t_m = B_m + Σ_{k ∈ hep(m)} ⌈(t_m + J_k)/T_k⌉ C_k          (level-m busy period; from t = C_m)
///     Q_m = ⌈(t_m + J_m)/T_m⌉                                    (instances in it)
///     w_m(q) = B_m + q C_m + Σ_{k ∈ hp(m)} ⌈(w_m(q) + J_k + τ_bit)/T_k⌉ C_k
///     R_m(q) = J_m + w_m(q) − q T_m + C_m,   R_m = max_{0 ≤ q < Q_m} R_m(q)
/// The original analysis (Tindell et al. 1994) examined q = 0 only; the paper shows that it
/// is optimistic when an instance's own previous frame pushes into its busy period, and
/// the busy-period check over all Q_m instances fixes it. Both are given here, the
/// original for comparison. A message longer than 8 bytes (network.hpp segments it into
/// frames of ≤ 8 bytes queued back to back with its identifier) is a stream with
/// `leading_frames` 8-byte frames before its last frame: C_m is the whole message, a higher-
/// priority frame may win the arbitration at each frame boundary, so (fixed preemption
/// points, the last frame F_m non-preemptive)
///     w_m(q) = B_m + q C_m + (C_m − F_m) + Σ_{k ∈ hp(m)} ⌈(w_m(q) + J_k + τ_bit)/T_k⌉ C_k
///     R_m(q) = J_m + w_m(q) − q T_m + F_m,
/// and it blocks higher-priority streams for one frame only (B: the longest single frame of
/// lp(m)). With leading_frames 0 this is the analysis above. All arithmetic is in integer ns; a fixed-point iteration that
/// passes 10^4 · max T (hep utilization ≥ 1) reports the stream as unbounded.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "oneshot/engine/can_bus.hpp"
#include "oneshot/engine/sim_time.hpp"

namespace oneshot::engine {

/// A periodic (or sporadic, minimum inter-arrival T) stream of CAN frames.
struct CanStream {
  std::string name;             ///< Identifier for reports.
  std::uint32_t id = 0;         ///< CAN identifier (priority: lower wins).
  std::size_t payload_bytes = 8;  ///< Data bytes (0 … 8).
  Duration period{0};           ///< T.
  Duration jitter{0};           ///< J: queuing jitter (release to queue).
  Duration deadline{0};         ///< D (from release).
  std::size_t leading_frames = 0;  ///< 8-byte frames of the same message queued before its last one (payload_bytes).
};

/// The analysis of one stream.
struct CanStreamBound {
  Duration transmission{0};     ///< C (the whole message: every frame).
  Duration blocking{0};         ///< B.
  Duration busy_period{0};      ///< t (revised analysis).
  std::size_t instances = 0;    ///< Q.
  Duration response{0};         ///< R (worst case from release to end of transmission).
  Duration response_original{0};  ///< R of the original analysis (q = 0 only).
  bool bounded = true;          ///< False when the busy period does not close.
  bool schedulable = true;      ///< bounded and R ≤ D.
};

/// Worst-case response times of `streams` on a bus of `config` (identifiers must be distinct).
std::vector<CanStreamBound> can_response_times(const std::vector<CanStream>& streams, const CanBusConfig& config);

}  // namespace oneshot::engine
