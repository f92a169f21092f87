/// @file petc_controller.hpp
/// @brief The PETC controller node of numre-petc.md §4–5: NUMRE on each arrival, the
///        cascade prediction of H + 1 future inputs, and the MTM trigger on the packet.
///
/// On the arrival of y_k (k − k_prev = N periods after the previous one):
///  1. the NUMRE predicts N periods with the inputs the actuator applied (known: the packet
///     in force, its last entry held beyond H) and corrects with y_k. The cascade that built
///     the packet in force stored its model trajectory x_r (x_r(k_sent + l), l = 0 … H + 1;
///     beyond, x_r ← A^j x_r + Γ(j) u_H from the span table), and the inputs cancel in
///        x̂(k|k−N) = x_r(k) + A^N (x̂(k−N|k−N) − x_r(k−N))      (no packet yet: x_r = 0),
///     so the prediction costs the same for every N (numre_estimator.hpp);
///  2. the first cascade step from x̂(k|k) and the law state stored with the packet in
///     force at k gives u_k:
///        ŷ = C x̂, d̂ = observer(ŷ, C̄ x̂), u_{k+l} = law(k + l, r − ŷ) − d̂, x̂ ← A x̂ + B u_{k+l}
///     (over the model's compile-time structure: the dense sums with exact zeros skipped);
///  3. send the packet if (ū − u_k)² > σ_c u_k² + δ_c (ū = first entry of the last packet
///     sent), or k − k_sent ≥ k_max (safety), or on the first arrival: only then the cascade
///     runs on to l = H, written straight into the packet in force (a withheld cascade is
///     never applied, so it is not computed); otherwise the packet in force stays and the
///     estimator keeps propagating its inputs.
/// Arrivals are untrusted (frame_checks.hpp): a non-finite y, a y outside the sensor's range
/// (once set) or a k beyond the sequence window is refused and counted (no packet); a
/// restarted sensor is re-acquired on its R-th arrival: no prediction over the unknown
/// interval then, and the packet in force (numbered in the old periods) is re-based by a
/// send on that arrival (kFirst when the trigger has no cause of its own). A correction
/// that turns the NUMRE non-finite resets it (counted, last_status() = kNonFinite) and
/// sends nothing.
/// A cascade with a non-finite entry or end state is withheld and the packet in force stays,
/// with no second packet buffer: the cascade is a deterministic function of (x̂(k|k), the
/// law state at k, k, r), so the packet in force is kept as its seed (x̂, law snapshot,
/// k_sent, r at the send: N + 1 values and one snapshot) and, if a cascade turns non-finite
/// part way through the buffer, the same code regenerates the packet in force from that seed
/// bit for bit. x̂ is finite here (the estimator resets otherwise) and the law state comes
/// from a finite cascade, so non-finite can only come from an overflow inside the cascade
/// (a huge reference or an unstable law or model over H steps): rare, paid only then.
/// Storage: H + 2 law states (the state before each entry and after the last; only the law's
/// mode states when it has them, LawStore), H + 2 model states, 2(H + 1) inputs and d̂:
/// 19 KB in float for H = 200, plus the estimator's span table (28 KB): 49 KB in all,
/// DSP-class memory (brief §10).
#pragma once

#include <cstddef>
#include <cstdint>
#include <type_traits>

#include "oneshot/finite.hpp"
#include "oneshot/matrix.hpp"
#include "oneshot/node/frame_checks.hpp"
#include "oneshot/node/mtm_trigger.hpp"
#include "oneshot/node/numre_estimator.hpp"
#include "oneshot/node/send_cause.hpp"
#include "oneshot/status.hpp"

namespace oneshot::node {

/// How a packet entry stores a law: the whole law, or only Law::Modes (modes() /
/// set_modes()) when the law has them (the constants stay in the node's initial law).
template <typename L, typename = void>
struct LawStore {
  using Type = L;  ///< Stored per entry.
  /// What to store.
  static constexpr Type save(const L& l) { return l; }
  /// Restores into `l` (a copy of the initial law).
  static constexpr void load(L& l, const Type& t) { l = t; }
};
/// Laws with mode states.
template <typename L>
struct LawStore<L, std::void_t<typename L::Modes>> {
  using Type = typename L::Modes;  ///< Stored per entry.
  /// What to store.
  static constexpr Type save(const L& l) { return l.modes(); }
  /// Restores into `l` (a copy of the initial law).
  static constexpr void load(L& l, const Type& t) { l.set_modes(t); }
};

/// Counters of a PETC controller (drops and refusals by cause in the FrameRefusals part).
struct PetcStatistics : FrameRefusals {
  std::uint32_t estimator_resets = 0;  ///< Corrections that turned non-finite (NUMRE reset).
  std::uint32_t withheld = 0;          ///< Cascades with a non-finite entry (not sent).
};

/// PETC controller with an N-state NUMRE, a packet of H + 1 inputs, a control law `Law`
/// (u = law.step(k, e), copyable), a disturbance estimate `Observer` and the model's
/// compile-time structure (numre_structure.hpp; the default assumes nothing; a model that
/// does not fit it must be refused first: fits()).
template <typename S, std::size_t N, std::size_t H, typename Law, typename Observer,
          typename Structure = DenseModelStructure<N>>
class PetcController {
 public:
  static constexpr std::size_t kEntries = H + 1;  ///< Inputs per packet.
  using Estimator = NumreEstimator<S, N, Structure>;  ///< The NUMRE.

  /// What the cascade carries from one period to the next besides x̂.
  struct LawState {
    Law law;        ///< Controller modes.
    Observer obs;   ///< Disturbance observer.
  };
  /// What a packet entry stores of a LawState (LawStore: the law's modes when it has them).
  struct Snapshot {
    typename LawStore<Law>::Type law{};  ///< Law (or its modes).
    Observer obs{};                      ///< Disturbance observer.
  };

  /// Controller at rest (x̂ = 0, P = 0, no packet in force).
  constexpr PetcController(const NumreModel<S, N>& model, NoiseAccumulation acc, const Law& law,
                           const Observer& obs, const MtmTrigger<S, 1>& trigger, S reference)
      : est_(model, acc), initial_{law, obs}, trigger_(trigger), reference_(reference) {}

  /// True when `model` fits Structure (the node must not be built on it otherwise).
  static constexpr bool fits(const NumreModel<S, N>& model) { return Estimator::fits(model); }

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
    arrival_status_ = count_frame(then_check(check_payload(yv, range_), [&] { return frame_status(gate_.offer(k)); }), stats_);
    if (!accepted(arrival_status_)) return SendCause::kNone;
    if (arrival_status_ == FrameStatus::kReacquired) rebase_ = have_packet_;
    // A re-acquired arrival (or one before the re-basing send) predicts nothing: the
    // interval since the last arrival is unknown, and the packet in force is in old periods.
    if (arrivals_ > 0 && arrival_status_ == FrameStatus::kOk && !rebase_)
      est_.predict_along(k - k_prev_, reference_state(k_prev_), reference_state(k));
    status_ = est_.correct(y);
    ++arrivals_;
    k_prev_ = k;
    if (status_ == Status::kNonFinite) {
      ++stats_.estimator_resets;
      return SendCause::kNone;
    }
    // The law state in force at k: stored with the packet in force.
    LawState ls = initial_;
    if (have_packet_) {
      const std::uint32_t idx = k - k_sent_;
      ls = restore(idx <= H ? states_[idx] : states_[H + 1]);
    }
    const LawState ls0 = ls;
    // First cascade step, then the controller trigger on its input.
    Vector<S, N> x;
    S d_hat = S(0);
    const S u0 = cascade_step(k, reference_, ls, est_.state(), x, d_hat);
    cascade_macs_ += kStepMacs + (ls.law.macs() - ls0.law.macs()) + (ls.obs.macs() - ls0.obs.macs());
    if (!is_finite(u0)) {  // nothing written yet: the packet in force stays as it is
      ++stats_.withheld;
      return SendCause::kNone;
    }
    Vector<S, 1> u0v;
    u0v[0] = u0;
    SendCause cause = trigger_.evaluate(k, u0v);
    if (cause == SendCause::kNone && rebase_) cause = SendCause::kFirst;
    if (cause == SendCause::kNone) return cause;
    // The cascade runs on to l = H straight into the packet in force.
    states_[0] = snapshot(ls0);
    packet_[0] = u0;
    d_hat_[0] = d_hat;
    trajectory_[0] = est_.state();
    trajectory_[1] = x;
    if (write_entries(k, 1, reference_, ls) != Status::kOk) {
      ++stats_.withheld;
      if (have_packet_) {
        regenerate();
      } else {  // no packet in force: back to none (applied() = 0, packet() all zero)
        for (std::size_t l = 0; l < kEntries; ++l) {
          packet_[l] = S(0);
          d_hat_[l] = S(0);
        }
      }
      return SendCause::kNone;
    }
    trigger_.on_sent(k, u0v);
    seed_x_ = est_.state();
    seed_state_ = states_[0];
    seed_reference_ = reference_;
    k_sent_ = k;
    have_packet_ = true;
    rebase_ = false;
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
  /// The last sent cascade (kEntries inputs): the packet in force (a withheld cascade stops
  /// after its first entry).
  constexpr const S* last_cascade() const { return packet_; }
  /// d̂ of each entry of the last sent cascade (kEntries values).
  constexpr const S* last_cascade_d_hat() const { return d_hat_; }
  /// Model state the packet in force predicts at period j: x_r(j) of step 1 (0 before any).
  constexpr Vector<S, N> reference_state(std::uint32_t j) {
    if (!have_packet_) return Vector<S, N>{};
    const std::uint32_t idx = j - k_sent_;
    if (idx <= H + 1) return trajectory_[idx];
    Vector<S, N> x = trajectory_[H + 1];
    est_.advance(idx - static_cast<std::uint32_t>(H + 1), x, packet_[H]);
    return x;
  }
  /// The estimator.
  constexpr const Estimator& estimator() const { return est_; }
  /// Status of the last correction (kNonFinite: the NUMRE was reset).
  [[nodiscard]] constexpr Status last_status() const { return status_; }
  /// Status of the last arrival's frame checks (refusals counted by cause in statistics()).
  [[nodiscard]] constexpr FrameStatus arrival_status() const { return arrival_status_; }
  /// Counters.
  constexpr const PetcStatistics& statistics() const { return stats_; }
  /// Multiply-adds: estimator + cascades (model, law, observer).
  constexpr std::uint64_t macs() const { return est_.macs() + cascade_macs_; }

 private:
  NumreEstimator<S, N, Structure> est_;
  LawState initial_;
  MtmTrigger<S, 1> trigger_;
  S reference_;
  std::uint32_t k_prev_ = 0;
  std::uint32_t k_sent_ = 0;
  std::uint32_t arrivals_ = 0;
  bool have_packet_ = false;
  S packet_[kEntries]{};
  S d_hat_[kEntries]{};
  Snapshot states_[H + 2]{};
  Vector<S, N> trajectory_[H + 2]{};
  std::uint64_t cascade_macs_ = 0;
  Status status_ = Status::kOk;
  FrameStatus arrival_status_ = FrameStatus::kOk;
  SequenceGate gate_{};
  ValueRange<S, 1> range_{};
  PetcStatistics stats_{};
  bool rebase_ = false;  ///< Re-acquired: the packet in force is numbered in the old periods.
  /// Seed of the packet in force (what regenerates it): x̂ and law state at k_sent, r.
  Vector<S, N> seed_x_{};
  Snapshot seed_state_{};
  S seed_reference_{};

  /// What entry l stores of the cascade's law state.
  static constexpr Snapshot snapshot(const LawState& ls) { return {LawStore<Law>::save(ls.law), ls.obs}; }
  /// The law state a snapshot stands for (into a copy of the initial law).
  constexpr LawState restore(const Snapshot& sn) const {
    LawState ls = initial_;
    LawStore<Law>::load(ls.law, sn.law);
    ls.obs = sn.obs;
    return ls;
  }

  /// Multiply-adds of one cascade step over Structure: x ← A x + B u, ŷ, d̂ (the law and the
  /// observer count their own).
  static constexpr std::uint64_t kStepMacs = structure_size<Structure, N>() + mask_count(Structure::kB) +
                                             mask_count(Structure::kC) + mask_count(Structure::kCbar);

  /// One cascade step at period k towards reference r from the model state x into x_next
  /// (not aliasing x): ŷ = C x, d̂ = observer(ŷ, C̄ x), u = law(k, r − ŷ) − d̂,
  /// x_next = A x + B u, each over Structure's nonzeros in straight-line code (skipping A's
  /// zeros by a run-time index list cost more instructions on the M4F than the dense
  /// product). Returns u; d̂ in `d_hat`. Its multiply-adds (kStepMacs) are counted by the caller.
  /// Always inlined: in the loop of write_entries the law's states stay in registers (out of
  /// line the M4F pays ~35 more instructions per step loading and storing them).
  [[gnu::always_inline]] constexpr S cascade_step(std::uint64_t k, S r, LawState& ls, const Vector<S, N>& x, Vector<S, N>& x_next, S& d_hat) {
    const NumreModel<S, N>& m = est_.model();
    const S y_hat = masked_dot<Structure::kC>(m.c, x);
    const S d_model = masked_dot<Structure::kCbar>(m.c_bar, x);
    d_hat = ls.obs.estimate(y_hat, d_model);
    const S u = ls.law.step(k, r - y_hat) - d_hat;
    ls.obs.commit(u);
    static_cast<void>(masked_step<Structure>(m.a, m.b, x, u, x_next));
    return u;
  }

  /// Entries l = from … H of the packet from period k (entry `from` from `ls` and the model
  /// state trajectory_[from]), written into the packet in force with their law states and
  /// model trajectory (each step straight from trajectory_[l] into trajectory_[l + 1]).
  /// kNonFinite when an entry or the end state is non-finite (or their sum overflows): the
  /// buffer is then overwritten with a packet that must not be used.
  [[nodiscard]] constexpr Status write_entries(std::uint32_t k, std::size_t from, S r, LawState& ls) {
    const LawState ls0 = ls;
    S sum = S(0);  // non-finite when any entry is (NaN, ±∞ absorb under +), or it overflows
    for (std::size_t l = from; l <= H; ++l) {
      states_[l] = snapshot(ls);
      S d_hat = S(0);
      const S u = cascade_step(static_cast<std::uint64_t>(k) + l, r, ls, trajectory_[l], trajectory_[l + 1], d_hat);
      packet_[l] = u;
      d_hat_[l] = d_hat;
      sum = sum + u;
    }
    states_[H + 1] = snapshot(ls);
    cascade_macs_ += (H + 1 - from) * kStepMacs + (ls.law.macs() - ls0.law.macs()) +
                     (ls.obs.macs() - ls0.obs.macs());
    for (std::size_t i = 0; i < N; ++i) sum = sum + trajectory_[H + 1][i];
    return is_finite(sum) ? Status::kOk : Status::kNonFinite;
  }

  /// Regenerates the packet in force from its seed (bit for bit: the same cascade).
  constexpr void regenerate() {
    LawState ls = restore(seed_state_);
    trajectory_[0] = seed_x_;
    // The same cascade from the same seed gives the same bits, which were finite when the
    // packet was sent: this cannot fail.
    static_cast<void>(write_entries(k_sent_, 0, seed_reference_, ls));
  }
};

}  // namespace oneshot::node
