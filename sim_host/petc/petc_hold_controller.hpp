/// @file petc_hold_controller.hpp
/// @brief The loop's controller of the cases without NUMRE (TTS, PETC holding the last y),
///        wrapped for the petc run like the NUMRE node (petc_sim.cpp).
#pragma once

#include <algorithm>
#include <cstdint>

#include "oneshot/node/interlaced_controller.hpp"
#include "oneshot/node/mtm_trigger.hpp"
#include "oneshot/node/send_cause.hpp"
#include "petc_sim.hpp"

namespace oneshot::sim::petc {

/// The interlaced law of the study (1 fast + 2 slow modes).
using Law = node::InterlacedController<double, 1, 2>;
/// The MTM trigger of a scalar signal.
using Trigger = node::MtmTrigger<double, 1>;

/// TTS and PETC without NUMRE: hold the last y, run the law every period on arrival.
class HoldController {
 public:
  /// Law, controller trigger, `always` (TTS: send every period), reference r.
  HoldController(const Law& law, const Trigger& trig, bool always, double r)
      : law_(law), trig_(trig), always_(always), r_(r) {}
  /// y_k arrived: the law catches up over the periods since the last arrival with the held
  /// y, then e_k = r − y_k gives u_k; the packet is u_k held (H + 1 entries) when sent.
  node::SendCause arrive(std::uint32_t k, double y) {
    const std::uint64_t before = law_.macs();
    if (any_)
      for (std::uint32_t j = k_prev_ + 1; j != k; ++j) static_cast<void>(law_.step(j, r_ - y_held_));
    const double u = law_.step(k, r_ - y);
    multiplicity_ = any_ ? k - k_prev_ : 0;
    y_held_ = y;
    k_prev_ = k;
    any_ = true;
    last_macs_ = law_.macs() - before;
    Vector<double, 1> uv;
    uv[0] = u;
    const node::SendCause cause = always_ ? node::SendCause::kPeriodic : trig_.evaluate(k, uv);
    if (cause != node::SendCause::kNone) {
      trig_.on_sent(k, uv);
      std::fill(packet_, packet_ + kHorizon + 1, u);
    }
    return cause;
  }
  /// The packet in force (H + 1 entries).
  const double* packet() const { return packet_; }
  /// Multiply-adds of the law so far.
  std::uint64_t macs() const { return law_.macs(); }
  /// Multiply-adds of the last arrival.
  std::uint64_t last_macs() const { return last_macs_; }
  /// Periods since the previous arrival (0 on the first).
  std::uint32_t multiplicity() const { return multiplicity_; }
  /// No disturbance estimate: 0.
  double d_hat(std::uint32_t) const { return 0; }
  /// No estimator state to record.
  void record_state(RunTrace&) const {}
  /// Restart: the power-on controller `p` again.
  void restart_as(const HoldController& p) { *this = p; }
  /// No estimator.
  std::uint32_t estimator_resets() const { return 0; }

 private:
  Law law_;
  Trigger trig_;
  bool always_;
  double r_;
  std::uint32_t k_prev_ = 0;
  bool any_ = false;
  double y_held_ = 0;
  std::uint32_t multiplicity_ = 0;
  std::uint64_t last_macs_ = 0;
  double packet_[kHorizon + 1]{};
};

}  // namespace oneshot::sim::petc
