/// @file petc_frames.hpp
/// @brief The petc loop's messages as frames under a fault spec (docs/faults.md, "Study
///        petc"): what the controller and the actuator check before they use one.
///
/// Links "sc" (sensor → controller: [k: u32][y: f64][crc: u16]) and "ca" (controller →
/// actuator: [k: u32][u_k … u_{k+H}: f64 × (H + 1)][crc: u16]), engine/sequenced_frame.hpp.
/// Both links have no delay and no loss, and the nodes share the period clock, so the only
/// genuine frame is the one stamped with the receiver's current period k_now. A receiver
/// refuses a frame whose CRC-16 does not match its bytes (corrupt: a flipped bit), a frame
/// with a non-finite value (refused_non_finite) or a value outside its range (refused_out_of_range),
/// drops a frame not newer than the last one it accepted (stale: a duplicate, a replay) and
/// refuses any other k ≠ k_now (refused_sequence: forged or corrupted).
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <vector>

#include "oneshot/engine/sequenced_frame.hpp"
#include "oneshot/node/frame_checks.hpp"

namespace oneshot::sim::petc {

/// What a receiver counts (FrameRefusals + stale).
struct FrameCounts : node::FrameRefusals {
  std::uint32_t stale = 0;  ///< Not newer than the last accepted frame (dropped).
};

/// The checks of one receiving node: values first, then the stamp against its own clock.
class FrameReceiver {
 public:
  /// Values must lie in [−range, range] (range > 0).
  explicit FrameReceiver(double range) : range_(range) {}
  /// Decodes `frame` (stamp into k, `n` values into v) and checks it with accept(): true when
  /// it may be used at period `k_now`; a CRC mismatch is counted as corrupt.
  bool receive(const std::vector<std::uint8_t>& frame, std::uint32_t& k, double* v, std::size_t n, std::uint32_t k_now) {
    switch (engine::decode_sequenced_frame(frame, k, v, n)) {
      case engine::SequencedFrameStatus::kOk: break;
      case engine::SequencedFrameStatus::kCorrupt: ++counts_.corrupt; return false;
      case engine::SequencedFrameStatus::kMalformed: throw std::logic_error("petc: a frame changed its size");  // no fault does
    }
    return accept(k, v, n, k_now);
  }
  /// True when the frame (stamp k, `n` values) may be used at period `k_now`; counts otherwise.
  bool accept(std::uint32_t k, const double* v, std::size_t n, std::uint32_t k_now) {
    for (std::size_t i = 0; i < n; ++i)
      if (!std::isfinite(v[i])) {
        ++counts_.refused_non_finite;
        return false;
      }
    for (std::size_t i = 0; i < n; ++i)
      if (!(std::fabs(v[i]) <= range_)) {
        ++counts_.refused_out_of_range;
        return false;
      }
    if (any_ && !node::seq_newer(k, last_)) {
      ++counts_.stale;
      return false;
    }
    if (k != k_now) {
      ++counts_.refused_sequence;
      return false;
    }
    last_ = k;
    any_ = true;
    return true;
  }
  /// Power-on state (a restarted node): no frame accepted yet; the counters stay.
  void forget() { any_ = false; }
  /// Counters.
  const FrameCounts& counts() const { return counts_; }

 private:
  double range_;
  std::uint32_t last_ = 0;
  bool any_ = false;
  FrameCounts counts_{};
};

}  // namespace oneshot::sim::petc
