/// @file mtm_trigger.hpp
/// @brief The NUMRE brief's trigger (§3, §5): relative/absolute mixed threshold (MTM),
///        time-triggered safety and the send after a known reference change.
///
///     send if (ȳ_i − y_i,k)² > σ y_i,k² + δ   for some component i     (eq. 6 / 22; ȳ = last sent)
///          or k − k_last ≥ k_max                                       (eq. 7, safety; 0: off)
///          or k − k_ref = k_ref,max                                    (eq. 8, after a reference change)
/// The first sample is sent (eq. 8 with delay 0: a plant at rest never triggers otherwise).
#pragma once

#include <cstddef>
#include <cstdint>

#include "oneshot/matrix.hpp"
#include "oneshot/node/last_sent.hpp"
#include "oneshot/node/message.hpp"
#include "oneshot/node/send_cause.hpp"

namespace oneshot::node {

/// MTM trigger on P components with relative weight σ and absolute term δ.
template <typename S, std::size_t P>
class MtmTrigger : public LastSent<S, P> {
 public:
  /// Thresholds σ, δ (≥ 0), safety after `k_max` samples (0: off), reference send
  /// `k_ref_max` samples after a notified reference change.
  constexpr MtmTrigger(S sigma, S delta, std::uint32_t k_max, std::uint32_t k_ref_max)
      : sigma_(sigma), delta_(delta), k_max_(k_max), k_ref_max_(k_ref_max) {}

  /// A known reference change at sample k (the send follows k_ref,max samples later).
  constexpr void notify_reference_change(SequenceNumber k) {
    k_ref_ = k;
    ref_pending_ = true;
  }

  /// Decision for sample k with value y.
  constexpr SendCause evaluate(SequenceNumber k, const Vector<S, P>& y) const {
    const SendCause c = this->first_or_delta(y, [&](S last, S yi, std::size_t) {
      const S d = last - yi;
      return sigma_ * yi * yi + delta_ < d * d;
    });
    if (c != SendCause::kNone) return c;
    if (ref_pending_ && k - k_ref_ == k_ref_max_) return SendCause::kReference;
    return this->time_due(k, k_max_) ? SendCause::kTime : SendCause::kNone;
  }
  /// Remembers the value and index of a send (and ends a pending reference send).
  constexpr void on_sent(SequenceNumber k, const Vector<S, P>& y) {
    LastSent<S, P>::on_sent(k, y);
    if (ref_pending_ && k - k_ref_ >= k_ref_max_) ref_pending_ = false;
  }

 private:
  S sigma_;
  S delta_;
  std::uint32_t k_max_;
  std::uint32_t k_ref_max_;
  SequenceNumber k_ref_ = 0;
  bool ref_pending_ = false;
};

}  // namespace oneshot::node
