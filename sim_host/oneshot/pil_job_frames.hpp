/// @file pil_job_frames.hpp
/// @brief The PIL frames of a recorded job: its sample request and the raw values of the
///        firmware's reply (pil_experiments.cpp, pil_exectime.cpp).
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "oneshot/app/pil_protocol.hpp"
#include "simulation.hpp"

namespace oneshot::sim {

/// The PIL sample request of a recorded job: sample and actuation instants (µs), ADC and
/// set-point codes.
inline app::pil::Frame sample_frame(const JobRecord& r) {
  app::pil::Frame f;
  app::pil::Writer w(f);
  w.u(static_cast<std::uint32_t>(std::llround(r.t_sample_s * 1e6)), 4);
  w.u(static_cast<std::uint32_t>(std::llround(r.t_apply_s * 1e6)), 4);
  w.s(r.y_code, 2);
  w.s(r.setpoint_code, 2);
  return f;
}

/// u[0], x[0..n), k[0] of a job reply (the firmware's raw values), empty when malformed.
inline std::vector<std::int32_t> reply_values(const app::pil::Frame& reply, std::size_t n) {
  app::pil::Reader in(reply);
  in.u(1);  // status
  in.s(4);  // tau
  in.u(1);  // saturated
  const std::size_t writes = in.u(1);
  for (std::size_t i = 0; i < writes; ++i) in.u(3);
  std::vector<std::int32_t> v;
  for (std::size_t i = 0; i < n + 2; ++i) v.push_back(static_cast<std::int32_t>(in.u(4)));
  if (in.bad()) return {};
  return v;
}

}  // namespace oneshot::sim
