/// @file send_cause.hpp
/// @brief Why a node sent (or did not send) a message: the trigger rules' common result.
#pragma once

#include <cstdint>

namespace oneshot::node {

/// Outcome of a trigger rule for one sample.
enum class SendCause : std::uint8_t {
  kNone = 0,      ///< No send.
  kFirst,         ///< The first sample (every event-based sender starts with a send).
  kPeriodic,      ///< Time-triggered: every sample (or every n-th).
  kDelta,         ///< The value moved by more than its threshold (send-on-delta, MTM).
  kTime,          ///< Too long without a send (modified send-on-delta's δt, MTM's safety k_max).
  kReference,     ///< A known reference change k_ref,max steps ago (MTM, eq. 8).
};

}  // namespace oneshot::node
