/// @file sequenced_frame.hpp
/// @brief The byte form of a study message that is a sequence number and values:
///        [seq: u32 little-endian][v₀ … v_{n−1}: IEEE 754 binary64], and its FrameLayout.
///
/// Studies whose nodes pass values on the engine (dropping, petc, sod) send each message in this
/// form through their links' LinkFaults, so a fault can turn a value NaN, flip bits, forge
/// the sequence number, duplicate or replay the frame; the receiver decodes it and checks
/// it like any untrusted frame. Host byte order is little-endian (x86-64, AArch64).
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <vector>

#include "oneshot/engine/frame_layout.hpp"

namespace oneshot::engine {

/// Layout of a sequenced frame: u32 sequence number at 0, doubles from byte 4.
inline constexpr FrameLayout kSequencedFrameLayout{0, 4, 4, 8};

/// Encodes `seq` and the `n` values at `values`: 4 + 8n bytes.
inline std::vector<std::uint8_t> encode_sequenced_frame(std::uint32_t seq, const double* values, std::size_t n) {
  std::vector<std::uint8_t> b(4 + 8 * n);
  for (std::size_t j = 0; j < 4; ++j) b[j] = static_cast<std::uint8_t>(seq >> (8 * j));
  if (n > 0) std::memcpy(b.data() + 4, values, 8 * n);
  return b;
}

/// Decodes a frame of `n` values into `seq`, `values`; false (nothing written) when its size
/// is not 4 + 8n bytes.
inline bool decode_sequenced_frame(const std::vector<std::uint8_t>& b, std::uint32_t& seq, double* values, std::size_t n) {
  if (b.size() != 4 + 8 * n) return false;
  seq = 0;
  for (std::size_t j = 0; j < 4; ++j) seq |= static_cast<std::uint32_t>(b[j]) << (8 * j);
  if (n > 0) std::memcpy(values, b.data() + 4, 8 * n);
  return true;
}

}  // namespace oneshot::engine
