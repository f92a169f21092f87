/// @file last_sent.hpp
/// @brief What an event trigger remembers of its last send, and the rules every event
///        trigger shares: the first sample is sent, a component beyond its threshold sends
///        (kDelta), and the time rule k − k_last ≥ n sends (kTime; n = 0: off).
///
/// The sender never learns whether a packet arrived: ȳ = y and k_last = k are stored at
/// every send. SendOnDeltaTrigger and MtmTrigger derive from it (no virtual functions: each
/// trigger is used through its own type) and differ only in the threshold test.
#pragma once

#include <cstddef>
#include <cstdint>

#include "oneshot/matrix.hpp"
#include "oneshot/node/message.hpp"
#include "oneshot/node/send_cause.hpp"

namespace oneshot::node {

/// Memory of the last send of a trigger on P components in scalar S.
template <typename S, std::size_t P>
class LastSent {
 public:
  /// Remembers the value and index of a send.
  constexpr void on_sent(SequenceNumber k, const Vector<S, P>& y) {
    last_ = y;
    k_last_ = k;
    any_sent_ = true;
  }

 protected:
  /// kFirst before any send; kDelta when exceeds(ȳ_i, y_i, i) for some component i; else kNone.
  template <typename Exceeds>
  constexpr SendCause first_or_delta(const Vector<S, P>& y, Exceeds&& exceeds) const {
    if (!any_sent_) return SendCause::kFirst;
    for (std::size_t i = 0; i < P; ++i)
      if (exceeds(last_[i], y[i], i)) return SendCause::kDelta;
    return SendCause::kNone;
  }
  /// The time rule: k − k_last ≥ n (never when n = 0).
  constexpr bool time_due(SequenceNumber k, std::uint32_t n) const { return n > 0 && k - k_last_ >= n; }

 private:
  Vector<S, P> last_{};
  SequenceNumber k_last_ = 0;
  bool any_sent_ = false;
};

}  // namespace oneshot::node
