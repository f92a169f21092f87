/// @file frame_faults.hpp
/// @brief The frame faults of one link (a decorator of its frames, fault_spec.hpp) and
///        the checks and counters shared by every user of a fault spec.
///
/// Each clause acting on a link draws from its own streams "fault/<i>/<kind>/<link>/hit"
/// (one uniform per frame, whatever happens: the hits of a clause never move when another
/// clause or the link's delays change) and ".../pick" (which value, which bits; drawn only
/// on a hit), i the clause's position in the spec. A frame meets the clauses in spec order:
/// nan, flip and forge_seq change it in place (when the layout has a CRC, nan and forge_seq
/// rewrite it — a wrong sender sends a valid frame — while flip leaves it: a transfer error
/// the receiver's CRC check refuses), dup and replay add frames delivered right
/// after it (same arrival, after it in order), travelling with it (lost with it). The same
/// seed and spec give the same bytes whatever the thread count or the process (the engine
/// and the live relay use this class alike).
#pragma once

#include <cstdint>
#include <deque>
#include <string>
#include <utility>
#include <vector>

#include "oneshot/engine/fault_spec.hpp"
#include "oneshot/engine/frame_layout.hpp"
#include "oneshot/engine/random_stream.hpp"
#include "oneshot/engine/sim_time.hpp"

namespace oneshot::engine {

/// Faults injected, per kind; `skipped`: hits that found nothing to act on (no value, no
/// sequence number, no frame old enough to replay).
struct FaultCounters {
  std::uint64_t nan = 0;        ///< Values turned NaN.
  std::uint64_t flip = 0;       ///< Frames with inverted bits.
  std::uint64_t dup = 0;        ///< Duplicates delivered.
  std::uint64_t replay = 0;     ///< Old frames delivered again.
  std::uint64_t forge_seq = 0;  ///< Sequence numbers forged.
  std::uint64_t restart = 0;    ///< Node restarts.
  std::uint64_t skipped = 0;    ///< Hits without effect.
  /// Adds another set.
  FaultCounters& operator+=(const FaultCounters& o);
  /// Faults injected (all kinds, not the skipped).
  std::uint64_t injected() const { return nan + flip + dup + replay + forge_seq + restart; }
  /// Counts the effect of a clause of kind `k`.
  void count(FaultClause::Kind k);
};

/// The frame faults of one link.
class LinkFaults {
 public:
  /// The frame clauses of `spec` for link `link` (its own or every link) with the link's
  /// frame layout, streams of experiment seed `seed`.
  LinkFaults(const FaultSpec& spec, const std::string& link, const FrameLayout& layout, std::uint64_t seed);
  /// True when no clause acts on this link.
  bool empty() const { return active_.empty(); }
  /// Applies the faults to the frame sent at `sent` (payload `bytes`, changed in place);
  /// appends the frames to deliver right after it to `extra`.
  void apply(SimTime sent, std::vector<std::uint8_t>& bytes, std::vector<std::vector<std::uint8_t>>& extra);
  /// Counters.
  const FaultCounters& counters() const { return counters_; }

 private:
  struct Active {
    FaultClause clause;
    RandomStream hit;
    RandomStream pick;
    bool fired = false;
  };
  bool act(Active& a, SimTime sent, std::vector<std::uint8_t>& bytes, std::vector<std::vector<std::uint8_t>>& extra);

  std::vector<Active> active_;
  FrameLayout layout_;
  std::deque<std::pair<SimTime, std::vector<std::uint8_t>>> history_;  ///< Frames sent (replay).
  Duration keep_{0};  ///< Longest replay age: older frames are dropped from the history.
  FaultCounters counters_{};
};

/// Checks that every clause names an existing target: `link=` one of `links`, `node=` one
/// of `nodes`; InputError naming the clause and listing the names otherwise.
void check_fault_targets(const FaultSpec& spec, const std::vector<std::string>& links, const std::vector<std::string>& nodes);

/// The restart clauses of `spec` for node `node`: their instants (ns), in spec order.
std::vector<SimTime> restart_instants(const FaultSpec& spec, const std::string& node);

}  // namespace oneshot::engine
