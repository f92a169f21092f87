/// @file sequenced_frame.hpp
/// @brief The byte form of a study message that is a sequence number and values:
///        [seq: u32 little-endian][v₀ … v_{n−1}: IEEE 754 binary64][crc: u16 little-endian],
///        its decode status and its FrameLayout.
///
/// Studies whose nodes pass values on the engine (dropping, petc, sod) send each message in this
/// form through their links' LinkFaults, so a fault can turn a value NaN, flip bits, forge
/// the sequence number, duplicate or replay the frame; the receiver decodes it and checks
/// it like any untrusted frame. crc is the CRC-16/CCITT-FALSE (oneshot/crc16.hpp, the node
/// frames' check) of every byte before it: every 1-, 2- and 3-bit error and every burst of
/// ≤ 16 bits is detected, so a flipped bit is refused as corrupt instead of being used. Host
/// byte order is little-endian (x86-64, AArch64).
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <vector>

#include "oneshot/crc16.hpp"
#include "oneshot/engine/frame_layout.hpp"

namespace oneshot::engine {

/// Bytes of the CRC-16 that ends a sequenced frame.
inline constexpr std::size_t kSequencedFrameCrcBytes = 2;

/// Layout of a sequenced frame: u32 sequence number at 0, doubles from byte 4, CRC-16 last
/// (the fault injector re-seals a frame after `nan` and `forge_seq`, not after `flip`).
inline constexpr FrameLayout kSequencedFrameLayout{0, 4, 4, 8, kSequencedFrameCrcBytes};

/// Size in bytes of a sequenced frame of `n` values: 4 + 8n + 2.
constexpr std::size_t sequenced_frame_bytes(std::size_t n) { return 4 + 8 * n + kSequencedFrameCrcBytes; }

/// What decode_sequenced_frame() found, ordered by severity as node::FrameStatus's tail:
/// kOk < kCorrupt < kMalformed.
enum class [[nodiscard]] SequencedFrameStatus : std::uint8_t {
  kOk = 0,     ///< Right size, CRC matches: seq and values written.
  kCorrupt,    ///< Right size, but the CRC-16 does not match its bytes (altered on the way).
  kMalformed,  ///< Not sequenced_frame_bytes(n) bytes.
};

/// Encodes `seq` and the `n` values at `values`, sealed with their CRC-16: sequenced_frame_bytes(n) bytes.
inline std::vector<std::uint8_t> encode_sequenced_frame(std::uint32_t seq, const double* values, std::size_t n) {
  std::vector<std::uint8_t> b(sequenced_frame_bytes(n));
  for (std::size_t j = 0; j < 4; ++j) b[j] = static_cast<std::uint8_t>(seq >> (8 * j));
  if (n > 0) std::memcpy(b.data() + 4, values, 8 * n);
  const std::size_t body = b.size() - kSequencedFrameCrcBytes;
  const std::uint16_t crc = crc16_ccitt_false(b.data(), body);
  b[body] = static_cast<std::uint8_t>(crc & 0xFFU);
  b[body + 1] = static_cast<std::uint8_t>(crc >> 8);
  return b;
}

/// Decodes a frame of `n` values into `seq`, `values`; writes them only for kOk (size
/// checked first, then the CRC).
inline SequencedFrameStatus decode_sequenced_frame(const std::vector<std::uint8_t>& b, std::uint32_t& seq, double* values,
                                                   std::size_t n) {
  if (b.size() != sequenced_frame_bytes(n)) return SequencedFrameStatus::kMalformed;
  const std::size_t body = b.size() - kSequencedFrameCrcBytes;
  const auto got = static_cast<std::uint16_t>(b[body] | (b[body + 1] << 8));
  if (got != crc16_ccitt_false(b.data(), body)) return SequencedFrameStatus::kCorrupt;
  seq = 0;
  for (std::size_t j = 0; j < 4; ++j) seq |= static_cast<std::uint32_t>(b[j]) << (8 * j);
  if (n > 0) std::memcpy(values, b.data() + 4, 8 * n);
  return SequencedFrameStatus::kOk;
}

}  // namespace oneshot::engine
