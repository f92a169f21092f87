/// @file pil_protocol.hpp
/// @brief Processor-in-the-loop link between the host harness and the firmware (UART).
///
/// Frame on the wire (HDLC-like):  0x7E | stuffed(type, seq_lo, seq_hi, payload…, crc_lo, crc_hi) | 0x7E
/// Stuffing: 0x7E → 0x7D 0x5E, 0x7D → 0x7D 0x5D. CRC-16/CCITT-FALSE (poly 0x1021, init
/// 0xFFFF) over type, seq and payload. A receiver drops any frame whose CRC or length is
/// wrong and resynchronises at the next 0x7E, so a corrupt or lost byte costs one frame:
/// the host times out and resends the same sequence number, and the firmware answers a
/// repeated sequence number with its cached reply instead of running the job again.
/// Lock-step: one request, one reply. Integers are little-endian.
#pragma once

#include <cstddef>
#include <cstdint>

#include "oneshot/crc16.hpp"

namespace oneshot::app::pil {

inline constexpr std::uint8_t kFlag = 0x7E;     ///< Frame delimiter.
inline constexpr std::uint8_t kEscape = 0x7D;   ///< Escape byte.
inline constexpr std::uint8_t kEscapeXor = 0x20;  ///< Escaped byte = original ^ 0x20.
inline constexpr std::size_t kMaxPayload = 96;  ///< Largest payload in bytes.
inline constexpr std::uint8_t kProtocolVersion = 2;  ///< Version carried by kHello.

/// Message types (requests from the host; replies have bit 7 set).
enum class Type : std::uint8_t {
  kHello = 0x01,      ///< Firmware → host at boot and on request: what the image is.
  kConfig = 0x02,     ///< Select the approach, reset the controller: approach, noise model, initial codes.
  kSample = 0x03,     ///< Run the control job: now_us, next_actuation_us, ADC codes, set-point codes.
  kTick = 0x04,       ///< Raise the actuation timer interrupt at now_us.
  kCalibrate = 0x05,  ///< Call the instruction-count markers back to back (overhead).
  kEcho = 0x06,       ///< Link test: the payload comes back.
  kReply = 0x80,      ///< OR-ed into the type of a reply.
  kFault = 0xFF,      ///< Firmware → host: an invariant failed (payload: line, file).
};

/// A decoded frame.
struct Frame {
  Type type = Type::kEcho;                ///< Message type.
  std::uint16_t seq = 0;                  ///< Sequence number.
  std::uint8_t payload[kMaxPayload] = {}; ///< Payload bytes.
  std::size_t length = 0;                 ///< Payload length.
};

/// Encodes `f` into `out` (capacity ≥ 2·(kMaxPayload+5)+2); returns the byte count.
constexpr std::size_t encode(const Frame& f, std::uint8_t* out) {
  std::size_t n = 0;
  std::uint16_t crc = kCrc16Init;
  const auto put = [&](std::uint8_t b) {
    if (b == kFlag || b == kEscape) {
      out[n++] = kEscape;
      out[n++] = static_cast<std::uint8_t>(b ^ kEscapeXor);
    } else {
      out[n++] = b;
    }
  };
  const auto put_crc = [&](std::uint8_t b) {
    crc = crc16_update(crc, b);
    put(b);
  };
  out[n++] = kFlag;
  put_crc(static_cast<std::uint8_t>(f.type));
  put_crc(static_cast<std::uint8_t>(f.seq & 0xFFU));
  put_crc(static_cast<std::uint8_t>(f.seq >> 8));
  for (std::size_t i = 0; i < f.length; ++i) put_crc(f.payload[i]);
  const std::uint16_t c = crc;
  put(static_cast<std::uint8_t>(c & 0xFFU));
  put(static_cast<std::uint8_t>(c >> 8));
  out[n++] = kFlag;
  return n;
}

/// Byte-at-a-time decoder; feed() returns true when a valid frame is in frame().
class Decoder {
 public:
  /// Consumes one byte.
  [[nodiscard]] constexpr bool feed(std::uint8_t b) {
    if (b == kFlag) {
      const bool ok = !overflow_ && !escape_ && finish();
      reset();
      return ok;
    }
    if (overflow_) return false;
    if (b == kEscape) {
      escape_ = true;
      return false;
    }
    if (escape_) {
      b = static_cast<std::uint8_t>(b ^ kEscapeXor);
      escape_ = false;
    }
    if (used_ >= sizeof(buffer_)) {
      overflow_ = true;
      ++dropped_;
      return false;
    }
    buffer_[used_++] = b;
    return false;
  }
  /// The last valid frame.
  constexpr const Frame& frame() const { return frame_; }
  /// Frames dropped for a bad CRC, length or overflow.
  constexpr std::uint32_t dropped() const { return dropped_; }

 private:
  [[nodiscard]] constexpr bool finish() {
    if (used_ == 0) return false;          // back-to-back flags: nothing to do
    if (used_ < 5) {
      ++dropped_;
      return false;
    }
    std::uint16_t crc = kCrc16Init;
    for (std::size_t i = 0; i + 2 < used_; ++i) crc = crc16_update(crc, buffer_[i]);
    const auto got = static_cast<std::uint16_t>(buffer_[used_ - 2] | (buffer_[used_ - 1] << 8));
    if (crc != got) {
      ++dropped_;
      return false;
    }
    frame_.type = static_cast<Type>(buffer_[0]);
    frame_.seq = static_cast<std::uint16_t>(buffer_[1] | (buffer_[2] << 8));
    frame_.length = used_ - 5;
    for (std::size_t i = 0; i < frame_.length; ++i) frame_.payload[i] = buffer_[3 + i];
    return true;
  }
  constexpr void reset() {
    used_ = 0;
    escape_ = false;
    overflow_ = false;
  }

  std::uint8_t buffer_[kMaxPayload + 5] = {};
  std::size_t used_ = 0;
  bool escape_ = false;
  bool overflow_ = false;
  std::uint32_t dropped_ = 0;
  Frame frame_{};
};

/// Little-endian payload writer.
class Writer {
 public:
  /// Writes into `f`'s payload.
  constexpr explicit Writer(Frame& f) : f_(&f) { f.length = 0; }
  /// Appends an unsigned integer of `bytes` bytes.
  constexpr void u(std::uint32_t v, std::size_t bytes) {
    for (std::size_t i = 0; i < bytes && f_->length < kMaxPayload; ++i) {
      f_->payload[f_->length++] = static_cast<std::uint8_t>((v >> (8 * i)) & 0xFFU);
    }
  }
  /// Appends a signed integer of `bytes` bytes (two's complement).
  constexpr void s(std::int32_t v, std::size_t bytes) { u(static_cast<std::uint32_t>(v), bytes); }

 private:
  Frame* f_;
};

/// Little-endian payload reader; reads past the end give 0 and set bad().
class Reader {
 public:
  /// Reads `f`'s payload.
  constexpr explicit Reader(const Frame& f) : f_(&f) {}
  /// Reads an unsigned integer of `bytes` bytes.
  constexpr std::uint32_t u(std::size_t bytes) {
    std::uint32_t v = 0;
    for (std::size_t i = 0; i < bytes; ++i) {
      if (pos_ >= f_->length) {
        bad_ = true;
        return 0;
      }
      v |= static_cast<std::uint32_t>(f_->payload[pos_++]) << (8 * i);
    }
    return v;
  }
  /// Reads a signed integer of `bytes` bytes (sign-extended).
  constexpr std::int32_t s(std::size_t bytes) {
    const std::uint32_t v = u(bytes);
    const std::uint32_t sign = std::uint32_t{1} << (8 * bytes - 1);
    return bytes >= 4 ? static_cast<std::int32_t>(v) : static_cast<std::int32_t>((v ^ sign)) - static_cast<std::int32_t>(sign);
  }
  /// A read went past the payload.
  constexpr bool bad() const { return bad_; }

 private:
  const Frame* f_;
  std::size_t pos_ = 0;
  bool bad_ = false;
};

/// First word of a kFault payload: what went wrong (otherwise the line of a failed invariant).
inline constexpr std::uint32_t kFaultHard = 0xFFFFFFFFU;              ///< Hard fault.
inline constexpr std::uint32_t kFaultUnknownRequest = 0xFFFFFFFEU;    ///< Request type not known.
inline constexpr std::uint32_t kFaultMalformedRequest = 0xFFFFFFFDU;  ///< Wrong payload length or value.

/// Approach id of the generated C99 job of the image's format (B's job; an image without one refuses it).
inline constexpr std::uint8_t kCJobApproach = 5;
/// Approach id of the generated C99 job's own-arithmetic twin: q15 in fixed-point images,
/// float_poly in float table images (others refuse it).
inline constexpr std::uint8_t kCJobOwnArithApproach = 6;
/// Largest approach id of kConfig: 0–4 are A–E, 5 and 6 the generated C99 jobs.
inline constexpr std::uint8_t kMaxApproach = kCJobOwnArithApproach;

/// kConfig: approach (0–6), noise model (0 constant, 1 exact), initial PWM code per input.
template <std::size_t M>
struct ConfigRequest {
  std::uint8_t approach = 0;       ///< Approach A–E as 0–4, the generated C jobs as 5, 6.
  bool exact_noise = false;        ///< Exact Q_d(τ) instead of the constant Q.
  std::int32_t codes[M] = {};      ///< Initial PWM code of each input (0–65535).
  /// Exact payload length: 1 + 1 + 2·M bytes.
  static constexpr std::size_t kLength = 2 + 2 * M;
};

/// kSample: sample instant, next actuation instant, ADC and set-point codes per output.
template <std::size_t P>
struct SampleRequest {
  std::uint32_t now_us = 0;             ///< Sample instant.
  std::uint32_t next_actuation_us = 0;  ///< Next actuation instant.
  std::int32_t adc[P] = {};             ///< ADC code of each output (signed 16-bit).
  std::int32_t setpoint[P] = {};        ///< Set-point code of each output (signed 16-bit).
  /// Exact payload length: 4 + 4 + 2·P + 2·P bytes.
  static constexpr std::size_t kLength = 8 + 4 * P;
};

/// kTick: the actuation instant.
struct TickRequest {
  std::uint32_t now_us = 0;  ///< Actuation instant.
  /// Exact payload length.
  static constexpr std::size_t kLength = 4;
};

/// Decodes a kConfig payload; false (out untouched) unless the length is exact and the
/// approach and noise model are known: a truncated request must not run on zeros.
template <std::size_t M>
[[nodiscard]] constexpr bool decode(const Frame& f, ConfigRequest<M>& out) {
  if (f.length != ConfigRequest<M>::kLength) return false;
  Reader in(f);
  ConfigRequest<M> r;
  const std::uint32_t approach = in.u(1);
  const std::uint32_t noise = in.u(1);
  if (approach > kMaxApproach || noise > 1) return false;
  r.approach = static_cast<std::uint8_t>(approach);
  r.exact_noise = noise == 1;
  for (std::size_t j = 0; j < M; ++j) r.codes[j] = static_cast<std::int32_t>(in.u(2));
  if (in.bad()) return false;
  out = r;
  return true;
}

/// Decodes a kSample payload; false (out untouched) unless the length is exact.
template <std::size_t P>
[[nodiscard]] constexpr bool decode(const Frame& f, SampleRequest<P>& out) {
  if (f.length != SampleRequest<P>::kLength) return false;
  Reader in(f);
  SampleRequest<P> r;
  r.now_us = in.u(4);
  r.next_actuation_us = in.u(4);
  for (std::size_t o = 0; o < P; ++o) r.adc[o] = in.s(2);
  for (std::size_t o = 0; o < P; ++o) r.setpoint[o] = in.s(2);
  if (in.bad()) return false;
  out = r;
  return true;
}

/// Decodes a kTick payload; false (out untouched) unless the length is exact.
[[nodiscard]] constexpr bool decode(const Frame& f, TickRequest& out) {
  if (f.length != TickRequest::kLength) return false;
  Reader in(f);
  const std::uint32_t now = in.u(4);
  if (in.bad()) return false;
  out.now_us = now;
  return true;
}

}  // namespace oneshot::app::pil
