/// @file petc_controller.hpp
/// @brief The PETC controller node of numre-petc.md §4–5: NUMRE on each arrival, the
///        cascade prediction of H + 1 future inputs, and the MTM trigger on the packet.
///
/// On the arrival of y_k (k − k_prev = N periods after the previous one):
///  1. the NUMRE predicts N periods with the inputs the actuator applied (known: the packet
///     in force, its last entry held beyond H) and corrects with y_k;
///  2. cascade from x̂(k|k) and the law state stored with the packet in force at k:
///        for l = 0 … H: ŷ = C x̂, d̂ = observer(ŷ, C̄ x̂), u_{k+l} = law(k + l, r − ŷ) − d̂,
///                        x̂ ← A x̂ + B u_{k+l}
///  3. send the packet if (ū − u_k)² > σ_c u_k² + δ_c (ū = first entry of the last packet
///     sent), or k − k_sent ≥ k_max (safety), or on the first arrival; otherwise the packet
///     in force stays and the estimator keeps propagating its inputs.
/// Arrivals are untrusted (frame_checks.hpp): a non-finite y, a y outside the sensor's range
/// (once set) or a k beyond the sequence window is refused and counted (no packet); a
/// restarted sensor is re-acquired on its R-th arrival (no prediction over the unknown
/// interval then). A correction that turns the NUMRE non-finite resets it (counted,
/// last_status() = kNonFinite) and sends nothing; a cascade with a non-finite input is
/// withheld: the packet in force stays.
/// Storage: H + 2 law states (the state before each entry and after the last), 2(H + 1)
/// inputs: about 64 KB for H = 200 with the DOB, DSP-class memory (brief §10).
#pragma once

#include <cstddef>
#include <cstdint>

#include "oneshot/finite.hpp"
#include "oneshot/matrix.hpp"
#include "oneshot/node/frame_checks.hpp"
#include "oneshot/node/mtm_trigger.hpp"
#include "oneshot/node/numre_estimator.hpp"
#include "oneshot/node/send_cause.hpp"
#include "oneshot/status.hpp"

namespace oneshot::node {

/// Counters of a PETC controller (refusals by cause in the FrameRefusals part).
struct PetcStatistics : FrameRefusals {
  std::uint32_t stale = 0;             ///< Arrivals not newer than the last one (dropped).
  std::uint32_t estimator_resets = 0;  ///< Corrections that turned non-finite (NUMRE reset).
  std::uint32_t withheld = 0;          ///< Cascades with a non-finite input (not sent).
};

/// PETC controller with an N-state NUMRE, a packet of H + 1 inputs, a control law `Law`
/// (u = law.step(k, e), copyable) and a disturbance estimate `Observer`.
template <typename S, std::size_t N, std::size_t H, typename Law, typename Observer>
class PetcController {
 public:
  static constexpr std::size_t kEntries = H + 1;  ///< Inputs per packet.

  /// What the cascade carries from one period to the next besides x̂.
  struct LawState {
    Law law;        ///< Controller modes.
    Observer obs;   ///< Disturbance observer.
  };

  /// Controller at rest (x̂ = 0, P = 0, no packet in force).
  constexpr PetcController(const NumreModel<S, N>& model, NoiseAccumulation acc, const Law& law,
                           const Observer& obs, const MtmTrigger<S, 1>& trigger, S reference)
      : est_(model, acc), initial_{law, obs}, trigger_(trigger), reference_(reference) {}

  /// The reference from now on (a known change: the sensor is told separately).
  constexpr void set_reference(S r) { reference_ = r; }

  /// Accepts y in [y_min, y_max] only (the sensor's range from the design).
  constexpr void set_measurement_range(S y_min, S y_max) {
    Vector<S, 1> lo;
    Vector<S, 1> hi;
    lo[0] = y_min;
    hi[0] = y_max;
    range_ = ValueRange<S, 1>(lo, hi);
  }
  /// Sequence window W (the longest silence, periods) and re-acquisition count R.
  constexpr void set_sequence_window(std::uint32_t window, std::uint32_t reacquire) {
    gate_ = SequenceGate(window, reacquire);
  }

  /// Arrival of y at period k. Returns the send cause (kNone: no packet).
  constexpr SendCause on_arrival(std::uint32_t k, S y) {
    Vector<S, 1> yv;
    yv[0] = y;
    if (!check_payload(yv, range_, stats_)) return SendCause::kNone;
    const SequenceVerdict v = gate_.offer(k);
    if (v == SequenceVerdict::kStale) ++stats_.stale;
    if (!count_sequence(v, stats_)) return SendCause::kNone;
    if (arrivals_ > 0 && v == SequenceVerdict::kAccepted)
      for (std::uint32_t j = k_prev_; j != k; ++j) est_.predict(applied(j));
    status_ = est_.correct(y);
    ++arrivals_;
    if (status_ == Status::kNonFinite) {
      ++stats_.estimator_resets;
      k_prev_ = k;
      return SendCause::kNone;
    }
    k_prev_ = k;
    // The law state in force at k: stored with the packet in force.
    LawState ls = initial_;
    if (have_packet_) {
      const std::uint32_t idx = k - k_sent_;
      ls = idx <= H ? states_[idx] : states_[H + 1];
    }
    // Cascade.
    Vector<S, N> x = est_.state();
    const NumreModel<S, N>& m = est_.model();
    for (std::size_t l = 0; l <= H; ++l) {
      S y_hat = S(0);
      S d_model = S(0);
      for (std::size_t i = 0; i < N; ++i) {
        y_hat = y_hat + m.c[i] * x[i];
        d_model = d_model + m.c_bar[i] * x[i];
      }
      new_states_[l] = ls;
      const S d_hat = ls.obs.estimate(y_hat, d_model);
      const S u = ls.law.step(static_cast<std::uint64_t>(k) + l, reference_ - y_hat) - d_hat;
      ls.obs.commit(u);
      new_packet_[l] = u;
      new_d_hat_[l] = d_hat;
      x = m.a * x + m.b * u;
      cascade_macs_ += N * N + 3 * N;
    }
    new_states_[H + 1] = ls;
    cascade_macs_ += (ls.law.macs() - new_states_[0].law.macs()) + (ls.obs.macs() - new_states_[0].obs.macs());
    for (std::size_t l = 0; l < kEntries; ++l)
      if (!is_finite(new_packet_[l])) {
        ++stats_.withheld;
        return SendCause::kNone;
      }
    // Controller trigger on the first entry.
    Vector<S, 1> u0;
    u0[0] = new_packet_[0];
    const SendCause cause = trigger_.evaluate(k, u0);
    if (cause != SendCause::kNone) {
      trigger_.on_sent(k, u0);
      for (std::size_t l = 0; l < kEntries; ++l) {
        packet_[l] = new_packet_[l];
        d_hat_[l] = new_d_hat_[l];
      }
      for (std::size_t l = 0; l < H + 2; ++l) states_[l] = new_states_[l];
      k_sent_ = k;
      have_packet_ = true;
    }
    return cause;
  }

  /// Input the actuator applies at period j under the packet in force (0 before any).
  constexpr S applied(std::uint32_t j) const {
    if (!have_packet_) return S(0);
    const std::uint32_t idx = j - k_sent_;
    return idx > H ? packet_[H] : packet_[idx];
  }
  /// d̂ the packet in force assumed at period j (0 before any).
  constexpr S disturbance_estimate(std::uint32_t j) const {
    if (!have_packet_) return S(0);
    const std::uint32_t idx = j - k_sent_;
    return idx > H ? d_hat_[H] : d_hat_[idx];
  }
  /// The packet in force (kEntries values) and the period it was sent at.
  constexpr const S* packet() const { return packet_; }
  /// Period of the packet in force.
  constexpr std::uint32_t packet_start() const { return k_sent_; }
  /// The last arrival's cascade (kEntries inputs), sent or withheld.
  constexpr const S* last_cascade() const { return new_packet_; }
  /// d̂ of each entry of the last arrival's cascade (kEntries values).
  constexpr const S* last_cascade_d_hat() const { return new_d_hat_; }
  /// The estimator.
  constexpr const NumreEstimator<S, N>& estimator() const { return est_; }
  /// Status of the last correction (kNonFinite: the NUMRE was reset).
  constexpr Status last_status() const { return status_; }
  /// Counters.
  constexpr const PetcStatistics& statistics() const { return stats_; }
  /// Multiply-adds: estimator + cascades (model, law, observer).
  constexpr std::uint64_t macs() const { return est_.macs() + cascade_macs_; }

 private:
  NumreEstimator<S, N> est_;
  LawState initial_;
  MtmTrigger<S, 1> trigger_;
  S reference_;
  std::uint32_t k_prev_ = 0;
  std::uint32_t k_sent_ = 0;
  std::uint32_t arrivals_ = 0;
  bool have_packet_ = false;
  S packet_[kEntries]{};
  S d_hat_[kEntries]{};
  S new_packet_[kEntries]{};
  S new_d_hat_[kEntries]{};
  LawState states_[H + 2]{};
  LawState new_states_[H + 2]{};
  std::uint64_t cascade_macs_ = 0;
  Status status_ = Status::kOk;
  SequenceGate gate_{};
  ValueRange<S, 1> range_{};
  PetcStatistics stats_{};
};

}  // namespace oneshot::node
