/// @file send_on_delta_trigger.hpp
/// @brief Send-on-delta and its modification with a time rule (send-on-delta brief §2).
///
///     (2a)  |y_i,k − y_last,i| > δy,i      for some component i
///     (2b)  k − k_last ≥ n_t               (modified only; n_t = round(δt/T) ≥ 1)
///
/// y_last and k_last are stored at every send; the sender never learns whether the packet
/// arrived. The first sample is always sent. Plain send-on-delta is n_t = 0 (rule 2b off).
#pragma once

#include <cstddef>
#include <cstdint>

#include "oneshot/matrix.hpp"
#include "oneshot/node/last_sent.hpp"
#include "oneshot/node/message.hpp"
#include "oneshot/node/send_cause.hpp"
#include "oneshot/scalar_traits.hpp"

namespace oneshot::node {

/// Send-on-delta on P components with thresholds δy; time rule after n_t samples (0: off).
template <typename S, std::size_t P>
class SendOnDeltaTrigger : public LastSent<S, P> {
 public:
  /// Thresholds `delta` (per component, ≥ 0) and the time rule `n_t` in samples (0: plain SOD).
  constexpr SendOnDeltaTrigger(const Vector<S, P>& delta, std::uint32_t n_t) : delta_(delta), n_t_(n_t) {}

  /// Decision for sample k with value y: kFirst, kDelta (2a), kTime (2b) or kNone.
  constexpr SendCause evaluate(SequenceNumber k, const Vector<S, P>& y) const {
    const SendCause c = this->first_or_delta(
        y, [&](S last, S yi, std::size_t i) { return delta_[i] < ScalarTraits<S>::abs(yi - last); });
    if (c != SendCause::kNone) return c;
    return this->time_due(k, n_t_) ? SendCause::kTime : SendCause::kNone;
  }

 private:
  Vector<S, P> delta_;
  std::uint32_t n_t_;
};

}  // namespace oneshot::node
