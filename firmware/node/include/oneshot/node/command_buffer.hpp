/// @file command_buffer.hpp
/// @brief Commands kept by sequence number until the actuator's timer asks for one
///        (a fixed ring, no heap).
///
/// Slot = seq mod Slots; a slot holds the newest command that mapped to it, so commands
/// for the next Slots − 1 periods can wait while older ones are overwritten. find(k) only
/// answers with the command stamped exactly k.
#pragma once

#include <cstddef>
#include <cstdint>

#include "oneshot/matrix.hpp"
#include "oneshot/node/message.hpp"

namespace oneshot::node {

/// Ring of `Slots` commands of M scalars S keyed by sequence number.
template <typename S, std::size_t M, std::size_t Slots>
class CommandBuffer {
  static_assert(Slots >= 1, "a command buffer needs at least one slot");

 public:
  /// Stores u for sequence number seq (replaces an older entry of the same slot): kOk, or
  /// kStale when the slot holds a newer command, which is kept.
  [[nodiscard]] constexpr FrameStatus store(SequenceNumber seq, const Vector<S, M>& u) {
    const Slot& s = slots_[seq % Slots];
    if (s.used && s.seq != seq && seq_newer(s.seq, seq)) return FrameStatus::kStale;
    replace(seq, u);
    return FrameStatus::kOk;
  }
  /// Stores u for sequence number seq whatever the slot held (the caller has checked that
  /// seq is one of Slots consecutive numbers it waits for, which map to distinct slots).
  constexpr void replace(SequenceNumber seq, const Vector<S, M>& u) {
    Slot& s = slots_[seq % Slots];
    s.used = true;
    s.seq = seq;
    s.u = u;
  }
  /// The command stamped `seq`, when present.
  constexpr bool find(SequenceNumber seq, Vector<S, M>& u) const {
    const Slot& s = slots_[seq % Slots];
    if (!s.used || s.seq != seq) return false;
    u = s.u;
    return true;
  }

 private:
  struct Slot {
    bool used = false;
    SequenceNumber seq = 0;
    Vector<S, M> u{};
  };
  Slot slots_[Slots] = {};
};

}  // namespace oneshot::node
