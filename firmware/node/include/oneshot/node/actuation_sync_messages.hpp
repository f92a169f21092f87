/// @file actuation_sync_messages.hpp
/// @brief The two messages of the actuation-synchronized loop that carry more than a
///        command (networked-actuation brief §1), and their little-endian wire form.
///
///   msg 1, actuator → sensor: ActuationRequest = (k, t_k, u applied at t_{k−1})
///   msg 2, sensor → controller: SampleReport = (k, t_s,k, τ_k = t_k − t_s,k, y_s,k, u echo)
///   msg 3, controller → actuator: Message<VectorPayload<S, M>> with seq = k (message.hpp)
/// The echo is the input really applied at t_{k−1} (the held value when the command was
/// late), so the controller predicts with what the plant got. Wire form: k (4) | instant
/// (4) | [τ_us (4, signed)] | scalars | crc (2), as in message.hpp (CRC-16/CCITT-FALSE of
/// the bytes before it).
#pragma once

#include <cstddef>
#include <cstdint>

#include "oneshot/matrix.hpp"
#include "oneshot/node/message.hpp"
#include "oneshot/time_us.hpp"

namespace oneshot::node {

/// msg 1: the actuator asks for the sample of period k, to be applied at t_k.
template <typename S, std::size_t M>
struct ActuationRequest {
  SequenceNumber k = 0;       ///< Period index of the actuation the sample serves.
  McuInstant t_k{};           ///< Actuation instant t_k (actuator clock, synchronized).
  Vector<S, M> u_applied{};   ///< Input applied at t_{k−1} (the echo).
};

/// msg 2: the sensor's sample for period k.
template <typename S, std::size_t P, std::size_t M>
struct SampleReport {
  SequenceNumber k = 0;       ///< Period index (copied from the request).
  McuInstant t_s{};           ///< Sampling instant t_s,k (sensor clock).
  std::int32_t tau_us = 0;    ///< τ_k = t_k − t_s,k (µs): the prediction horizon.
  Vector<S, P> y{};           ///< The sample y_s,k.
  Vector<S, M> u_applied{};   ///< The echo of the request.
};

/// Encoded size of an ActuationRequest.
template <typename S, std::size_t M>
constexpr std::size_t request_size() {
  return kHeaderBytes + M * detail::scalar_bytes<S>() + kCrcBytes;
}

/// Encoded size of a SampleReport.
template <typename S, std::size_t P, std::size_t M>
constexpr std::size_t report_size() {
  return kHeaderBytes + 4 + (P + M) * detail::scalar_bytes<S>() + kCrcBytes;
}

/// Encodes a request into `out`; returns the byte count.
template <typename S, std::size_t M>
std::size_t encode(const ActuationRequest<S, M>& m, std::uint8_t* out) {
  static_assert(request_size<S, M>() <= kMaxMessageBytes, "request larger than kMaxMessageBytes");
  detail::put_le(out, m.k, 4);
  detail::put_le(out + 4, m.t_k.ticks(), 4);
  for (std::size_t i = 0; i < M; ++i) detail::put_scalar(out + kHeaderBytes + i * detail::scalar_bytes<S>(), m.u_applied[i]);
  return detail::seal(out, request_size<S, M>() - kCrcBytes);
}

/// Decodes a request: kOk, kMalformed (m untouched) when the size is not a request's, or
/// kCorrupt (m untouched) when the CRC does not match.
template <typename S, std::size_t M>
[[nodiscard]] FrameStatus decode(const std::uint8_t* in, std::size_t size, ActuationRequest<S, M>& m) {
  if (size != request_size<S, M>()) return FrameStatus::kMalformed;
  if (!detail::intact(in, size)) return FrameStatus::kCorrupt;
  m.k = static_cast<SequenceNumber>(detail::get_le(in, 4));
  m.t_k = McuInstant(static_cast<std::uint32_t>(detail::get_le(in + 4, 4)));
  for (std::size_t i = 0; i < M; ++i) m.u_applied[i] = detail::get_scalar<S>(in + kHeaderBytes + i * detail::scalar_bytes<S>());
  return FrameStatus::kOk;
}

/// Encodes a report into `out`; returns the byte count.
template <typename S, std::size_t P, std::size_t M>
std::size_t encode(const SampleReport<S, P, M>& m, std::uint8_t* out) {
  static_assert(report_size<S, P, M>() <= kMaxMessageBytes, "report larger than kMaxMessageBytes");
  constexpr std::size_t kB = detail::scalar_bytes<S>();
  detail::put_le(out, m.k, 4);
  detail::put_le(out + 4, m.t_s.ticks(), 4);
  detail::put_le(out + 8, static_cast<std::uint32_t>(m.tau_us), 4);
  for (std::size_t i = 0; i < P; ++i) detail::put_scalar(out + 12 + i * kB, m.y[i]);
  for (std::size_t i = 0; i < M; ++i) detail::put_scalar(out + 12 + (P + i) * kB, m.u_applied[i]);
  return detail::seal(out, report_size<S, P, M>() - kCrcBytes);
}

/// Decodes a report: kOk, kMalformed (m untouched) when the size is not a report's, or
/// kCorrupt (m untouched) when the CRC does not match.
template <typename S, std::size_t P, std::size_t M>
[[nodiscard]] FrameStatus decode(const std::uint8_t* in, std::size_t size, SampleReport<S, P, M>& m) {
  if (size != report_size<S, P, M>()) return FrameStatus::kMalformed;
  if (!detail::intact(in, size)) return FrameStatus::kCorrupt;
  constexpr std::size_t kB = detail::scalar_bytes<S>();
  m.k = static_cast<SequenceNumber>(detail::get_le(in, 4));
  m.t_s = McuInstant(static_cast<std::uint32_t>(detail::get_le(in + 4, 4)));
  const auto tau = static_cast<std::uint32_t>(detail::get_le(in + 8, 4));
  std::int32_t tau_s = 0;
  __builtin_memcpy(&tau_s, &tau, 4);  // two's complement reinterpretation
  m.tau_us = tau_s;
  for (std::size_t i = 0; i < P; ++i) m.y[i] = detail::get_scalar<S>(in + 12 + i * kB);
  for (std::size_t i = 0; i < M; ++i) m.u_applied[i] = detail::get_scalar<S>(in + 12 + (P + i) * kB);
  return FrameStatus::kOk;
}

}  // namespace oneshot::node
