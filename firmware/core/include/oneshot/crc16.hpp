/// @file crc16.hpp
/// @brief CRC-16/CCITT-FALSE, a nibble at a time (freestanding): the integrity check of the node
///        frames (node/message.hpp), of the PIL link (app/pil_protocol.hpp) and of the
///        simulator's sequenced frames (engine/sequenced_frame.hpp).
///
/// Generator g(x) = x^16 + x^12 + x^5 + 1 (poly 0x1021), MSB first, register initialized
/// to 0xFFFF, no reflection, no final XOR; check value: the CRC of the ASCII bytes
/// "123456789" is 0x29B1. Per byte b: crc ^= b << 8, then 8 times crc = (crc << 1) ^
/// (crc & 0x8000 ? 0x1021 : 0). Hamming distance 4 up to 32751 data bits: every 1-, 2- and
/// 3-bit error and every odd number of bit errors in a frame is detected, and every burst
/// of ≤ 16 bits. Four bits at a time from a 16-entry table (32 bytes of ROM): two look-ups
/// per byte instead of eight shift/XOR steps (the frames are checked on every send and
/// receive; the bitwise form cost the simulated studies up to half their event rate).
#pragma once

#include <cstddef>
#include <cstdint>

namespace oneshot {

/// Initial register value of CRC-16/CCITT-FALSE.
inline constexpr std::uint16_t kCrc16Init = 0xFFFF;

/// The register after shifting in four zero bits from `crc` (bitwise: 4 times crc = (crc << 1)
/// ^ (crc & 0x8000 ? 0x1021 : 0)); the table's generator.
constexpr std::uint16_t crc16_shift4(std::uint16_t crc) {
  for (int i = 0; i < 4; ++i) {
    const unsigned shifted = static_cast<unsigned>(crc) << 1U;
    crc = static_cast<std::uint16_t>((crc & 0x8000U) != 0U ? shifted ^ 0x1021U : shifted);
  }
  return crc;
}

/// The 16 nibble remainders: entry i is crc16_shift4(i << 12).
struct Crc16NibbleTable {
  std::uint16_t entry[16];  ///< Remainder of the top nibble i.
};
/// Builds the nibble table at compile time.
constexpr Crc16NibbleTable make_crc16_nibble_table() {
  Crc16NibbleTable t{};
  for (unsigned i = 0; i < 16U; ++i) t.entry[i] = crc16_shift4(static_cast<std::uint16_t>(i << 12U));
  return t;
}
/// The nibble table (32 bytes of ROM).
inline constexpr Crc16NibbleTable kCrc16Nibbles = make_crc16_nibble_table();

/// CRC-16/CCITT-FALSE register `crc` after one more byte `byte`, a nibble at a time, high
/// nibble first: crc = (crc << 4) ^ T[(crc >> 12) ^ nibble].
constexpr std::uint16_t crc16_update(std::uint16_t crc, std::uint8_t byte) {
  const unsigned hi = static_cast<unsigned>(byte) >> 4U;
  const unsigned lo = static_cast<unsigned>(byte) & 0x0FU;
  crc = static_cast<std::uint16_t>((static_cast<unsigned>(crc) << 4U) ^ kCrc16Nibbles.entry[(static_cast<unsigned>(crc) >> 12U) ^ hi]);
  crc = static_cast<std::uint16_t>((static_cast<unsigned>(crc) << 4U) ^ kCrc16Nibbles.entry[(static_cast<unsigned>(crc) >> 12U) ^ lo]);
  return crc;
}

/// CRC-16/CCITT-FALSE of the `n` bytes at `data` (kCrc16Init for n = 0).
constexpr std::uint16_t crc16_ccitt_false(const std::uint8_t* data, std::size_t n) {
  std::uint16_t crc = kCrc16Init;
  for (std::size_t i = 0; i < n; ++i) crc = crc16_update(crc, data[i]);
  return crc;
}

}  // namespace oneshot
