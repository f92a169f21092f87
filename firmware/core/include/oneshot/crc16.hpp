/// @file crc16.hpp
/// @brief CRC-16/CCITT-FALSE, table-free (freestanding): the integrity check of the node
///        frames (node/message.hpp) and of the PIL link (app/pil_protocol.hpp).
///
/// Generator g(x) = x^16 + x^12 + x^5 + 1 (poly 0x1021), MSB first, register initialized
/// to 0xFFFF, no reflection, no final XOR; check value: the CRC of the ASCII bytes
/// "123456789" is 0x29B1. Per byte b: crc ^= b << 8, then 8 times crc = (crc << 1) ^
/// (crc & 0x8000 ? 0x1021 : 0). Hamming distance 4 up to 32751 data bits: every 1-, 2- and
/// 3-bit error and every odd number of bit errors in a frame is detected, and every burst
/// of ≤ 16 bits. Bitwise (no table): 8 shift/XOR steps per byte, 0 bytes of ROM.
#pragma once

#include <cstddef>
#include <cstdint>

namespace oneshot {

/// Initial register value of CRC-16/CCITT-FALSE.
inline constexpr std::uint16_t kCrc16Init = 0xFFFF;

/// CRC-16/CCITT-FALSE register `crc` after one more byte `byte`.
constexpr std::uint16_t crc16_update(std::uint16_t crc, std::uint8_t byte) {
  crc = static_cast<std::uint16_t>(crc ^ (static_cast<std::uint16_t>(byte) << 8));
  for (int i = 0; i < 8; ++i) {
    const unsigned shifted = static_cast<unsigned>(crc) << 1U;
    crc = static_cast<std::uint16_t>((crc & 0x8000U) != 0U ? shifted ^ 0x1021U : shifted);
  }
  return crc;
}

/// CRC-16/CCITT-FALSE of the `n` bytes at `data` (kCrc16Init for n = 0).
constexpr std::uint16_t crc16_ccitt_false(const std::uint8_t* data, std::size_t n) {
  std::uint16_t crc = kCrc16Init;
  for (std::size_t i = 0; i < n; ++i) crc = crc16_update(crc, data[i]);
  return crc;
}

}  // namespace oneshot
