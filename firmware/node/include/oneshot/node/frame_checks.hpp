/// @file frame_checks.hpp
/// @brief What a node checks before it uses a decoded frame (every frame is untrusted):
///        the sender, finite payload, payload in the design's range, and the sequence
///        window with re-acquisition of a restarted peer; each gives a FrameStatus
///        (frame_status.hpp), counted per cause.
///
/// Sequence window (docs/node_validation.md): with d = seq − last accepted (mod 2^32),
///     accepted     when 0 < d ≤ W                       (W = window, frames),
///     stale        when d read as signed is ≤ 0          (reordered, duplicate, old epoch),
///     jump         when d > W                            (refused_sequence: forged, corrupt).
/// A frame that is stale or a jump starts or extends a candidate epoch: it extends it when
/// 0 < seq − (previous candidate) ≤ W, else it starts a new one. The R-th consecutive
/// candidate frame is accepted and becomes the new base (re-acquisition); any accepted frame
/// of the current epoch clears the candidate. So a single forged frame never moves the base,
/// and a restarted peer (sequence from 0, or any new base) is followed again on its R-th
/// frame: R − 1 frames refused, i.e. within R sender periods for a periodic sender.
#pragma once

#include <cstddef>
#include <cstdint>

#include "oneshot/finite.hpp"
#include "oneshot/matrix.hpp"
#include "oneshot/node/frame_status.hpp"
#include "oneshot/node/message.hpp"

namespace oneshot::node {

/// Default forward window W (frames): a sender may skip up to W − 1 sequence numbers.
inline constexpr std::uint32_t kDefaultSequenceWindow = 4096;
/// Default re-acquisition count R: the R-th consecutive consistent frame of a new epoch is accepted.
inline constexpr std::uint32_t kDefaultReacquireFrames = 3;

/// Verdict of SequenceGate::offer().
enum class SequenceVerdict : std::uint8_t {
  kAccepted,    ///< Newer than the base and within the window.
  kReacquired,  ///< The R-th frame of a new epoch: accepted as the new base.
  kStale,       ///< Not newer than the base (dropped).
  kJump,        ///< Newer by more than the window (refused).
};

/// True when the verdict lets the frame through.
constexpr bool accepted(SequenceVerdict v) { return v == SequenceVerdict::kAccepted || v == SequenceVerdict::kReacquired; }

/// The sequence-window rule above for one peer's stream.
class SequenceGate {
 public:
  /// Window W ≥ 1 frames, re-acquisition after R ≥ 2 consistent frames (R < 2 is taken as 2).
  constexpr explicit SequenceGate(std::uint32_t window = kDefaultSequenceWindow,
                                  std::uint32_t reacquire = kDefaultReacquireFrames)
      : window_(window < 1 ? 1 : window), reacquire_(reacquire < 2 ? 2 : reacquire) {}

  /// Offers `seq`: the verdict; the base moves on kAccepted and kReacquired.
  [[nodiscard]] constexpr SequenceVerdict offer(SequenceNumber seq) {
    if (!any_) {
      take(seq);
      return SequenceVerdict::kAccepted;
    }
    const SequenceNumber d = seq - last_;  // mod 2^32
    const bool newer = seq_newer(seq, last_);
    if (newer && d <= window_) {
      take(seq);
      return SequenceVerdict::kAccepted;
    }
    const SequenceNumber dc = seq - candidate_;
    candidate_count_ = (candidate_count_ > 0 && dc != 0 && dc <= window_) ? candidate_count_ + 1 : 1;
    candidate_ = seq;
    if (candidate_count_ >= reacquire_) {
      take(seq);
      return SequenceVerdict::kReacquired;
    }
    return newer ? SequenceVerdict::kJump : SequenceVerdict::kStale;
  }
  /// True once a frame was accepted.
  constexpr bool any() const { return any_; }
  /// The base: sequence number of the last accepted frame (valid when any()).
  constexpr SequenceNumber last() const { return last_; }
  /// Forgets the stream (power-on state).
  constexpr void clear() {
    any_ = false;
    candidate_count_ = 0;
  }
  /// W.
  constexpr std::uint32_t window() const { return window_; }
  /// R.
  constexpr std::uint32_t reacquire_frames() const { return reacquire_; }

 private:
  constexpr void take(SequenceNumber seq) {
    last_ = seq;
    any_ = true;
    candidate_count_ = 0;
  }

  std::uint32_t window_;
  std::uint32_t reacquire_;
  SequenceNumber last_ = 0;
  SequenceNumber candidate_ = 0;
  std::uint32_t candidate_count_ = 0;
  bool any_ = false;
};

/// The frame status of a sequence verdict (jump → kRefusedSequence).
[[nodiscard]] constexpr FrameStatus frame_status(SequenceVerdict v) {
  switch (v) {
    case SequenceVerdict::kAccepted: return FrameStatus::kOk;
    case SequenceVerdict::kReacquired: return FrameStatus::kReacquired;
    case SequenceVerdict::kStale: return FrameStatus::kStale;
    case SequenceVerdict::kJump: return FrameStatus::kRefusedSequence;
  }
  return FrameStatus::kRefusedSequence;
}

/// The peer a node expects frames from (any sender until set).
class ExpectedSource {
 public:
  /// Frames from `address` only.
  constexpr void set(std::uint8_t address) {
    address_ = address;
    set_ = true;
  }
  /// kOk when `source` may send, kRefusedSource otherwise.
  [[nodiscard]] constexpr FrameStatus check(std::uint8_t source) const {
    return !set_ || source == address_ ? FrameStatus::kOk : FrameStatus::kRefusedSource;
  }

 private:
  std::uint8_t address_ = 0;
  bool set_ = false;
};

/// Closed range [lo, hi] per element of a vector of P scalars S (unchecked until set).
template <typename S, std::size_t P>
class ValueRange {
 public:
  /// Unchecked range (only finiteness applies).
  constexpr ValueRange() = default;
  /// [lo, hi] per element.
  constexpr ValueRange(const Vector<S, P>& lo, const Vector<S, P>& hi) : lo_(lo), hi_(hi), set_(true) {}
  /// True when every element of v is in range (or the range is unchecked).
  constexpr bool contains(const Vector<S, P>& v) const {
    if (!set_) return true;
    for (std::size_t i = 0; i < P; ++i)
      if (v[i] < lo_[i] || hi_[i] < v[i]) return false;
    return true;
  }
  /// True once set.
  constexpr bool is_set() const { return set_; }

 private:
  Vector<S, P> lo_{};
  Vector<S, P> hi_{};
  bool set_ = false;
};

/// Finite-and-in-range check of a payload vector: kOk, kRefusedNonFinite or kRefusedOutOfRange.
template <typename S, std::size_t P>
[[nodiscard]] constexpr FrameStatus check_payload(const Vector<S, P>& v, const ValueRange<S, P>& range) {
  if (!all_finite(v)) return FrameStatus::kRefusedNonFinite;
  return range.contains(v) ? FrameStatus::kOk : FrameStatus::kRefusedOutOfRange;
}

/// s when it is a refusal, else next() (the checks of a frame in order, the first refusal wins).
template <typename Next>
[[nodiscard]] constexpr FrameStatus then_check(FrameStatus s, Next&& next) {
  return s == FrameStatus::kOk ? next() : s;
}

}  // namespace oneshot::node
