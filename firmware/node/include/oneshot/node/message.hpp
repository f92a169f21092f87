/// @file message.hpp
/// @brief Messages between the nodes of a networked loop: sequence number, µs time stamp,
///        typed payload, and their little-endian wire form (freestanding).
///
/// Wire form (little-endian): seq (4 bytes) | stamp_us (4 bytes, the sender's wrapping
/// 32-bit µs clock) | payload scalars | crc (2 bytes). A float is its IEEE bits, a double
/// its 8 bytes, a Fixed its raw integer. crc is the CRC-16/CCITT-FALSE (poly 0x1021, init
/// 0xFFFF, oneshot/crc16.hpp) of every byte before it, sent low byte first: an end-to-end
/// check (AUTOSAR E2E style, with the sequence number) that a gateway, a driver or a link
/// without its own check cannot alter a frame unnoticed: every error of 1 to 3 bits, and
/// every burst of ≤ 16 bits, is caught (decode() gives kCorrupt). Sequence numbers wrap;
/// seq_newer() compares them in serial arithmetic (RFC 1982), right while the two are less
/// than 2^31 apart.
#pragma once

#include <cstddef>
#include <cstdint>
#include <type_traits>

#include "oneshot/crc16.hpp"
#include "oneshot/matrix.hpp"
#include "oneshot/node/frame_status.hpp"
#include "oneshot/time_us.hpp"

namespace oneshot::node {

/// Sequence number of a message (wraps at 2^32).
using SequenceNumber = std::uint32_t;

/// a is newer than b (serial-number arithmetic: a − b modulo 2^32 read as signed > 0).
constexpr bool seq_newer(SequenceNumber a, SequenceNumber b) { return earlier(McuInstant(b), McuInstant(a)); }

/// Largest encoded message (bytes), the size a network interface must carry.
inline constexpr std::size_t kMaxMessageBytes = 64;
/// Header bytes: seq and stamp.
inline constexpr std::size_t kHeaderBytes = 8;
/// Trailer bytes: the CRC-16 that ends every encoded message.
inline constexpr std::size_t kCrcBytes = 2;

/// A message: sender's sequence number, sender's clock when its payload was taken, payload.
template <typename Payload>
struct Message {
  SequenceNumber seq = 0;  ///< Sequence number (a sensor's sample index, a command's period …).
  McuInstant stamp{};      ///< Sender's µs clock when the payload was taken.
  Payload payload{};       ///< Contents.
};

/// A vector of P scalars S (a sample y, a command u, …) as a payload.
template <typename S, std::size_t P>
struct VectorPayload {
  Vector<S, P> value;  ///< The values.
};

namespace detail {
template <typename T, typename = void>
struct IsFixed : std::false_type {};
template <typename T>
struct IsFixed<T, std::void_t<typename T::StorageType>> : std::true_type {};

/// Bytes of one scalar on the wire.
template <typename S>
constexpr std::size_t scalar_bytes() {
  if constexpr (IsFixed<S>::value) {
    return sizeof(typename S::StorageType);
  } else {
    static_assert(std::is_floating_point_v<S>, "payload scalars are float, double or Fixed");
    return sizeof(S);
  }
}

/// Writes the low `n` bytes of `v` little-endian.
constexpr void put_le(std::uint8_t* out, std::uint64_t v, std::size_t n) {
  for (std::size_t i = 0; i < n; ++i) out[i] = static_cast<std::uint8_t>((v >> (8U * i)) & 0xFFU);
}
/// Reads `n` bytes little-endian.
constexpr std::uint64_t get_le(const std::uint8_t* in, std::size_t n) {
  std::uint64_t v = 0;
  for (std::size_t i = 0; i < n; ++i) v |= static_cast<std::uint64_t>(in[i]) << (8U * i);
  return v;
}

/// Appends the CRC-16 of the `n` bytes at `out` after them; returns n + kCrcBytes.
constexpr std::size_t seal(std::uint8_t* out, std::size_t n) {
  put_le(out + n, crc16_ccitt_false(out, n), kCrcBytes);
  return n + kCrcBytes;
}
/// True when the last kCrcBytes of the `size` bytes at `in` (size ≥ kCrcBytes) are the
/// CRC-16 of the bytes before them.
constexpr bool intact(const std::uint8_t* in, std::size_t size) {
  return get_le(in + size - kCrcBytes, kCrcBytes) == crc16_ccitt_false(in, size - kCrcBytes);
}

template <typename S>
void put_scalar(std::uint8_t* out, S v) {
  if constexpr (IsFixed<S>::value) {
    using St = typename S::StorageType;
    using U = std::make_unsigned_t<St>;
    put_le(out, static_cast<U>(v.raw()), sizeof(St));
  } else if constexpr (sizeof(S) == 4) {
    std::uint32_t bits = 0;
    __builtin_memcpy(&bits, &v, 4);
    put_le(out, bits, 4);
  } else {
    std::uint64_t bits = 0;
    __builtin_memcpy(&bits, &v, 8);
    put_le(out, bits, 8);
  }
}

template <typename S>
S get_scalar(const std::uint8_t* in) {
  if constexpr (IsFixed<S>::value) {
    using St = typename S::StorageType;
    using U = std::make_unsigned_t<St>;
    const U u = static_cast<U>(get_le(in, sizeof(St)));
    St raw = 0;
    __builtin_memcpy(&raw, &u, sizeof(St));  // two's complement reinterpretation
    return S::from_raw(raw);
  } else if constexpr (sizeof(S) == 4) {
    const auto bits = static_cast<std::uint32_t>(get_le(in, 4));
    S v{};
    __builtin_memcpy(&v, &bits, 4);
    return v;
  } else {
    const std::uint64_t bits = get_le(in, 8);
    S v{};
    __builtin_memcpy(&v, &bits, 8);
    return v;
  }
}
}  // namespace detail

/// Encoded size of Message<VectorPayload<S, P>>.
template <typename S, std::size_t P>
constexpr std::size_t encoded_size() {
  return kHeaderBytes + P * detail::scalar_bytes<S>() + kCrcBytes;
}

/// Encodes `m` into `out` (capacity ≥ encoded_size); returns the byte count.
template <typename S, std::size_t P>
std::size_t encode(const Message<VectorPayload<S, P>>& m, std::uint8_t* out) {
  static_assert(encoded_size<S, P>() <= kMaxMessageBytes, "message larger than kMaxMessageBytes");
  detail::put_le(out, m.seq, 4);
  detail::put_le(out + 4, m.stamp.ticks(), 4);
  for (std::size_t i = 0; i < P; ++i) detail::put_scalar(out + kHeaderBytes + i * detail::scalar_bytes<S>(), m.payload.value[i]);
  return detail::seal(out, encoded_size<S, P>() - kCrcBytes);
}

/// Decodes `size` bytes into `m`: kOk, kMalformed (m untouched) when the size is not the
/// encoded size, or kCorrupt (m untouched) when the CRC does not match.
template <typename S, std::size_t P>
[[nodiscard]] FrameStatus decode(const std::uint8_t* in, std::size_t size, Message<VectorPayload<S, P>>& m) {
  if (size != encoded_size<S, P>()) return FrameStatus::kMalformed;
  if (!detail::intact(in, size)) return FrameStatus::kCorrupt;
  m.seq = static_cast<SequenceNumber>(detail::get_le(in, 4));
  m.stamp = McuInstant(static_cast<std::uint32_t>(detail::get_le(in + 4, 4)));
  for (std::size_t i = 0; i < P; ++i) {
    m.payload.value[i] = detail::get_scalar<S>(in + kHeaderBytes + i * detail::scalar_bytes<S>());
  }
  return FrameStatus::kOk;
}

}  // namespace oneshot::node
