/// @file frame_layout.hpp
/// @brief Where a link's frames keep their sequence number and their values: what the
///        fault models need to forge a sequence number or turn a value into NaN, given by
///        the study (the engine knows no message format), and whether a CRC ends them.
#pragma once

#include <cstddef>

namespace oneshot::engine {

/// Layout of the frames a link carries (payload bytes, little-endian).
struct FrameLayout {
  std::size_t seq_offset = 0;    ///< Byte offset of the sequence number.
  std::size_t seq_bytes = 4;     ///< Its width (1–8 bytes; 0: the frames carry none).
  std::size_t value_offset = 0;  ///< First value (IEEE 754) …
  std::size_t value_bytes = 0;   ///< … each of 4 or 8 bytes, packed up to the CRC or the end (0: no values).
  std::size_t crc_bytes = 0;     ///< 2: the frame ends with the CRC-16/CCITT-FALSE of the bytes before it (low byte first); 0: no CRC.
};

}  // namespace oneshot::engine
