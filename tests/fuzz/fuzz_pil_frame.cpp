/// @file fuzz_pil_frame.cpp
/// @brief libFuzzer harness of the PIL frame decoder and the firmware's request decoders.
///
/// The input is a byte stream on the firmware's UART. Oracle for every frame the Decoder
/// accepts: its payload fits kMaxPayload; encoding it again and decoding gives the same
/// frame; a request decoder (sample, config, tick, for 1 and 2 channels) accepts it only at
/// its exact length and known values, and writing the decoded fields back gives the same
/// payload bytes (nothing read past the frame, nothing invented).
#include <cstdint>
#include <cstring>

#include "fuzz_oracle.hpp"
#include "oneshot/app/pil_protocol.hpp"

namespace pil = oneshot::app::pil;
using oneshot::fuzz::require;

namespace {

bool same_payload(const pil::Frame& a, const pil::Frame& b) {
  return a.length == b.length && std::memcmp(a.payload, b.payload, a.length) == 0;
}

template <std::size_t P>
void check_sample(const pil::Frame& f) {
  pil::SampleRequest<P> s;
  if (!pil::decode(f, s)) return;
  require(f.length == pil::SampleRequest<P>::kLength, "sample accepted at a wrong length");
  pil::Frame g;
  pil::Writer w(g);
  w.u(s.now_us, 4);
  w.u(s.next_actuation_us, 4);
  for (std::size_t o = 0; o < P; ++o) w.s(s.adc[o], 2);
  for (std::size_t o = 0; o < P; ++o) w.s(s.setpoint[o], 2);
  require(same_payload(f, g), "sample does not round-trip");
}

template <std::size_t M>
void check_config(const pil::Frame& f) {
  pil::ConfigRequest<M> c;
  if (!pil::decode(f, c)) return;
  require(f.length == pil::ConfigRequest<M>::kLength, "config accepted at a wrong length");
  require(c.approach <= pil::kMaxApproach, "unknown approach accepted");
  pil::Frame g;
  pil::Writer w(g);
  w.u(c.approach, 1);
  w.u(c.exact_noise ? 1U : 0U, 1);
  for (std::size_t j = 0; j < M; ++j) {
    require(c.codes[j] >= 0 && c.codes[j] <= 0xFFFF, "PWM code out of range");
    w.u(static_cast<std::uint32_t>(c.codes[j]), 2);
  }
  require(same_payload(f, g), "config does not round-trip");
}

void check_frame(const pil::Frame& f) {
  require(f.length <= pil::kMaxPayload, "payload longer than kMaxPayload");
  std::uint8_t wire[2 * (pil::kMaxPayload + 5) + 2];
  const std::size_t n = pil::encode(f, wire);
  pil::Decoder again;
  std::size_t frames = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (again.feed(wire[i])) {
      ++frames;
      require(again.frame().type == f.type && again.frame().seq == f.seq && same_payload(again.frame(), f),
              "frame does not survive encode + decode");
    }
  }
  require(frames == 1, "one encoded frame must decode to one frame");
  check_sample<1>(f);
  check_sample<2>(f);
  check_config<1>(f);
  check_config<2>(f);
  pil::TickRequest t;
  if (pil::decode(f, t)) require(f.length == pil::TickRequest::kLength, "tick accepted at a wrong length");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  pil::Decoder decoder;
  for (std::size_t i = 0; i < size; ++i) {
    if (decoder.feed(data[i])) check_frame(decoder.frame());
  }
  return 0;
}
