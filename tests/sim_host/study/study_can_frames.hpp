/// @file study_can_frames.hpp
/// @brief The closed form of a CAN message's transmission time the bus tests compare against.
#pragma once

#include <cstdint>

namespace oneshot::study::test_support {

/// Bits of a standard CAN data frame with s payload bytes under worst-case stuffing (Davis et
/// al. 2007, eq. 1): 34 + 8s stuffable bits, ⌊(34 + 8s − 1)/4⌋ stuff bits, 13 unstuffed.
inline std::int64_t stuffed_bits(std::int64_t s) { return 34 + 8 * s + 13 + (34 + 8 * s - 1) / 4; }

/// Transmission of a message of `bytes` in frames of ≤ 8 bytes at `bit_rate` (µs).
inline double message_us(std::int64_t bytes, std::int64_t bit_rate) {
  std::int64_t bits = 0;
  for (std::int64_t left = bytes; left > 0; left -= 8) bits += stuffed_bits(left > 8 ? 8 : left);
  return static_cast<double>(bits) * 1e6 / static_cast<double>(bit_rate);
}

}  // namespace oneshot::study::test_support
