/// @file fault_spec.hpp
/// @brief The fault-injection spec of a run: which faults, on which link or node, how often.
///
/// Text form (one clause per fault, clauses separated by ';', keys by ','):
///
///     nan:link=sc,rate=0.05; flip:bits=1,rate=0.01; dup:rate=0.02;
///     replay:age_ms=200,rate=0.01; forge_seq:at_s=2; restart:node=sensor,at_s=5
///
/// Frame faults (nan, flip, dup, replay, forge_seq) act on the frames of one link
/// (`link=NAME`) or of every link (no `link`), each frame with probability `rate` and/or
/// once, on the first frame sent at or after `at_s` (at least one of the two is required):
///   nan        one value of the frame (chosen uniformly) becomes a quiet NaN;
///   flip       `bits` distinct bits of the frame (chosen uniformly, 1–64, default 1) invert;
///   dup        the frame is delivered twice (the copy right after it);
///   replay     the newest frame of the link sent at least `age_ms` (default 200, 1–60000)
///              before this one is delivered again, right after it;
///   forge_seq  the frame's sequence number jumps by `jump` (default 2^31 − 2^16, 1–2^32−1).
/// Node fault: `restart:node=NAME,at_s=T` resets node NAME at T (the study's hook).
/// Parsing is strict: an unknown kind or key, a repeated key, a value out of range or a
/// clause that can never fire is an InputError naming the clause and the key. The empty
/// text is the empty spec (a clean run).
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "oneshot/engine/sim_time.hpp"

namespace oneshot::engine {

/// One fault of a spec.
struct FaultClause {
  /// What the fault does.
  enum class Kind : std::uint8_t { kNan, kFlip, kDup, kReplay, kForgeSeq, kRestart };
  Kind kind = Kind::kNan;       ///< Fault.
  std::string link;             ///< Frame faults: link name (empty: every link).
  std::string node;             ///< restart: node name.
  double rate = 0;              ///< Probability per frame, in [0, 1].
  bool once = false;            ///< Fires on the first frame at or after at_s (restart: at at_s).
  double at_s = 0;              ///< Instant of `once` (s, ≥ 0).
  std::uint32_t bits = 1;       ///< flip: bits inverted per hit.
  Duration age{200'000'000};    ///< replay: minimum age of the replayed frame.
  std::uint32_t jump = 0x7FFF0000u;  ///< forge_seq: added to the sequence number (2^31 − 2^16).
};

/// A parsed spec: the clauses in text order, and the text.
struct FaultSpec {
  std::vector<FaultClause> clauses;  ///< In text order (applied in this order to a frame).
  std::string text;                  ///< As given (for run files and summaries).
  /// True when no clause: the run is clean.
  bool empty() const { return clauses.empty(); }
};

/// The kind's name ("nan", "flip", "dup", "replay", "forge_seq", "restart").
const char* kind_name(FaultClause::Kind k);
/// True for the faults that act on frames (all but restart).
bool is_frame_fault(FaultClause::Kind k);
/// Parses the text form; InputError naming the clause ("fault clause 2 (dup)") and the key.
FaultSpec parse_fault_spec(std::string_view text);
/// A clause in canonical text form (every key, e.g. "dup:link=sc,rate=0.02").
std::string to_text(const FaultClause& c);

}  // namespace oneshot::engine
