/// @file frame_io.hpp
/// @brief The frame glue every node shares: draining the frames waiting at the board's
///        network interface, admitting one (decode, checks, count by cause), and sending
///        one message (encode, send, count).
///
/// A node's on_frame() is admit_frame() with its own checks; its on_receive() is
/// drain_frames() over on_frame(), keeping the worst status of the frames it handled.
#pragma once

#include <cstddef>
#include <cstdint>

#include "oneshot/node/frame_status.hpp"
#include "oneshot/node/message.hpp"

namespace oneshot::node {

/// Counters of the frames a node sends.
struct SendCounters {
  std::uint32_t sends = 0;    ///< Messages the interface took.
  std::uint32_t refused = 0;  ///< Sends the interface refused.
};

/// Outcome of one send.
enum class [[nodiscard]] SendResult : std::uint8_t {
  kSent,     ///< The interface took the frame.
  kRefused,  ///< The interface refused it (queue full, link down).
};

/// Encodes `m` and hands it to Board's interface for `destination`; counted into `c`.
template <typename Board, typename Msg>
[[nodiscard]] SendResult send_message(std::uint8_t destination, const Msg& m, SendCounters& c) {
  std::uint8_t bytes[kMaxMessageBytes];
  const std::size_t n = encode(m, bytes);
  if (Board::Net::send(destination, bytes, n)) {
    ++c.sends;
    return SendResult::kSent;
  }
  ++c.refused;
  return SendResult::kRefused;
}

/// One frame from `source`: decoded into a Msg (kMalformed when its size is not the Msg's,
/// kCorrupt when its CRC-16 does not match; `received` counts those that decode), then check(m, source) gives its status (use the frame when accepted());
/// the status is counted by cause into `r` and returned.
template <typename Msg, typename Check>
[[nodiscard]] FrameStatus admit_frame(std::uint8_t source, const std::uint8_t* bytes, std::size_t size,
                                      std::uint32_t& received, FrameRefusals& r, Check&& check) {
  Msg m;
  FrameStatus s = decode(bytes, size, m);
  if (s == FrameStatus::kOk) {
    ++received;
    s = check(m, source);
  }
  return count_frame(s, r);
}

/// Hands every frame waiting at Board's interface to on_frame(source, bytes, size) (which
/// returns its FrameStatus); returns the worst of them (kOk when none waited).
template <typename Board, typename OnFrame>
[[nodiscard]] FrameStatus drain_frames(OnFrame&& on_frame) {
  std::uint8_t bytes[kMaxMessageBytes];
  std::uint8_t source = 0;
  FrameStatus worst = FrameStatus::kOk;
  for (std::size_t n = Board::Net::receive(source, bytes, sizeof bytes); n != 0;
       n = Board::Net::receive(source, bytes, sizeof bytes))
    worst = worst_of(worst, on_frame(source, static_cast<const std::uint8_t*>(bytes), n));
  return worst;
}

}  // namespace oneshot::node
