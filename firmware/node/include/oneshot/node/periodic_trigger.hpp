/// @file periodic_trigger.hpp
/// @brief Time-triggered sending: every n-th sample (n = 1: every sample).
#pragma once

#include <cstddef>
#include <cstdint>

#include "oneshot/matrix.hpp"
#include "oneshot/node/message.hpp"
#include "oneshot/node/send_cause.hpp"

namespace oneshot::node {

/// Sends sample k when k mod every = 0.
template <typename S, std::size_t P>
class PeriodicTrigger {
 public:
  /// Every `every`-th sample (≥ 1).
  constexpr explicit PeriodicTrigger(std::uint32_t every = 1) : every_(every == 0 ? 1 : every) {}
  /// Decision for sample k.
  constexpr SendCause evaluate(SequenceNumber k, const Vector<S, P>&) const {
    return k % every_ == 0 ? SendCause::kPeriodic : SendCause::kNone;
  }
  /// Nothing to remember.
  constexpr void on_sent(SequenceNumber, const Vector<S, P>&) {}

 private:
  std::uint32_t every_;
};

}  // namespace oneshot::node
