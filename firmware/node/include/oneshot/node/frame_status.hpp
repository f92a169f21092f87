/// @file frame_status.hpp
/// @brief What became of one received frame, ordered by severity, and the per-cause counters
///        every node that receives frames keeps.
///
/// Every frame is untrusted: it is decoded (kMalformed when its size is not the message's,
/// kCorrupt when its CRC-16 does not match its bytes: message.hpp), then checked for its sender, finite payload, payload range and sequence window
/// (frame_checks.hpp). The first check that fails names the frame's status; count_frame()
/// adds it to the counter of its cause, so a refusal is never silent. Severity:
///     kOk < kReacquired < kStale < kRefusedSequence < kRefusedOutOfRange < kRefusedNonFinite
///         < kRefusedSource < kCorrupt < kMalformed
/// (used as is < dropped as old < refused as implausible < refused as not a frame of this
/// loop < refused as not what its sender sent < not a frame of this message at all).
#pragma once

#include <cstdint>

namespace oneshot::node {

/// Outcome of one received frame (values ordered by severity, see the file comment).
enum class [[nodiscard]] FrameStatus : std::uint8_t {
  kOk = 0,             ///< Decoded and accepted (decode(): the size fits, the CRC matches).
  kReacquired,         ///< Accepted as the new sequence base of a restarted peer.
  kStale,              ///< Not newer than the last accepted one: dropped.
  kRefusedSequence,    ///< Sequence jump beyond the window, or stamp outside its window.
  kRefusedOutOfRange,  ///< A payload value outside the design's range.
  kRefusedNonFinite,   ///< A payload scalar was NaN or ±∞.
  kRefusedSource,      ///< Sent by another node than the expected peer.
  kCorrupt,            ///< Right size, but its CRC-16 does not match its bytes (altered on the way).
  kMalformed,          ///< Did not decode (wrong size for the message).
};

/// True when the frame may be used (kOk or kReacquired).
constexpr bool accepted(FrameStatus s) { return s == FrameStatus::kOk || s == FrameStatus::kReacquired; }

/// The more severe of a and b (a on ties).
[[nodiscard]] constexpr FrameStatus worst_of(FrameStatus a, FrameStatus b) {
  return static_cast<std::uint8_t>(b) > static_cast<std::uint8_t>(a) ? b : a;
}

/// Frames dropped or refused before use, by cause (every node that decodes frames keeps one).
struct FrameRefusals {
  std::uint32_t malformed = 0;             ///< Frames that did not decode.
  std::uint32_t corrupt = 0;               ///< Frames whose CRC-16 did not match (bits altered on the way).
  std::uint32_t stale = 0;                 ///< Not newer than the last accepted one (dropped).
  std::uint32_t refused_non_finite = 0;    ///< A payload scalar was NaN or ±∞.
  std::uint32_t refused_out_of_range = 0;  ///< A payload value outside the design's range.
  std::uint32_t refused_source = 0;        ///< Sent by another node than the expected peer.
  std::uint32_t refused_sequence = 0;      ///< Sequence jump beyond the window, or stamp outside its window.
  std::uint32_t reacquired = 0;            ///< New sequence bases taken (restarted peer re-acquired).
};

/// Adds s to the counter of its cause (kOk counts nothing); returns s.
[[nodiscard]] constexpr FrameStatus count_frame(FrameStatus s, FrameRefusals& r) {
  switch (s) {
    case FrameStatus::kOk: break;
    case FrameStatus::kReacquired: ++r.reacquired; break;
    case FrameStatus::kStale: ++r.stale; break;
    case FrameStatus::kRefusedSequence: ++r.refused_sequence; break;
    case FrameStatus::kRefusedOutOfRange: ++r.refused_out_of_range; break;
    case FrameStatus::kRefusedNonFinite: ++r.refused_non_finite; break;
    case FrameStatus::kRefusedSource: ++r.refused_source; break;
    case FrameStatus::kCorrupt: ++r.corrupt; break;
    case FrameStatus::kMalformed: ++r.malformed; break;
  }
  return s;
}

/// Short name for logs and test messages (host side).
constexpr const char* to_string(FrameStatus s) {
  switch (s) {
    case FrameStatus::kOk: return "ok";
    case FrameStatus::kReacquired: return "reacquired";
    case FrameStatus::kStale: return "stale";
    case FrameStatus::kRefusedSequence: return "refused_sequence";
    case FrameStatus::kRefusedOutOfRange: return "refused_out_of_range";
    case FrameStatus::kRefusedNonFinite: return "refused_non_finite";
    case FrameStatus::kRefusedSource: return "refused_source";
    case FrameStatus::kCorrupt: return "corrupt";
    case FrameStatus::kMalformed: return "malformed";
  }
  return "unknown";
}

}  // namespace oneshot::node
