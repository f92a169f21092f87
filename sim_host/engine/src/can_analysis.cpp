/// @file can_analysis.cpp
/// @brief CAN worst-case response-time analysis (see can_analysis.hpp; Davis et al. 2007).
#include "oneshot/engine/can_analysis.hpp"

#include <algorithm>
#include <set>
#include <stdexcept>

namespace oneshot::engine {
namespace {

/// ⌈a/b⌉ for a ≥ 0, b > 0.
std::int64_t ceil_div(std::int64_t a, std::int64_t b) { return a <= 0 ? 0 : (a + b - 1) / b; }

}  // namespace

std::vector<CanStreamBound> can_response_times(const std::vector<CanStream>& streams, const CanBusConfig& config) {
  if (config.bit_rate <= 0 || 1'000'000'000 % config.bit_rate != 0) {
    throw std::invalid_argument("CAN analysis: bit rate must divide 1e9");
  }
  const std::int64_t tau = 1'000'000'000 / config.bit_rate;
  std::set<std::uint32_t> ids;
  std::int64_t max_period = 0;
  for (const CanStream& s : streams) {
    if (!ids.insert(s.id).second) throw std::invalid_argument("CAN analysis: identifier " + std::to_string(s.id) + " used twice");
    if (s.period.count() <= 0) throw std::invalid_argument("CAN analysis: stream '" + s.name + "' needs a positive period");
    if (s.jitter.count() < 0 || s.deadline.count() <= 0) {
      throw std::invalid_argument("CAN analysis: stream '" + s.name + "' needs jitter >= 0 and a positive deadline");
    }
    max_period = std::max(max_period, s.period.count());
  }
  const std::int64_t limit = 10'000 * max_period;
  // Per stream: its whole message c, its last frame f, its longest single frame np (what it blocks for).
  std::vector<std::int64_t> c(streams.size());
  std::vector<std::int64_t> f(streams.size());
  std::vector<std::int64_t> np(streams.size());
  const std::int64_t full = tau * can_frame_bits(8, config.extended_ids);
  for (std::size_t i = 0; i < streams.size(); ++i) {
    f[i] = tau * can_frame_bits(streams[i].payload_bytes, config.extended_ids);
    const auto lead = static_cast<std::int64_t>(streams[i].leading_frames);
    c[i] = lead * full + f[i];
    np[i] = lead > 0 ? std::max(full, f[i]) : f[i];
  }

  std::vector<CanStreamBound> out(streams.size());
  for (std::size_t m = 0; m < streams.size(); ++m) {
    const CanStream& sm = streams[m];
    CanStreamBound& r = out[m];
    r.transmission = Duration{c[m]};
    std::int64_t b = 0;  // B_m = max over lower-priority frames
    for (std::size_t k = 0; k < streams.size(); ++k)
      if (streams[k].id > sm.id) b = std::max(b, np[k]);
    r.blocking = Duration{b};
    const auto higher = [&](std::size_t k) { return streams[k].id < sm.id; };
    // Level-m busy period: t = B + Σ_{hep} ⌈(t + J_k)/T_k⌉ C_k, from t = C_m.
    std::int64_t t = c[m];
    for (;;) {
      std::int64_t next = b;
      for (std::size_t k = 0; k < streams.size(); ++k)
        if (higher(k) || k == m) next += ceil_div(t + streams[k].jitter.count(), streams[k].period.count()) * c[k];
      if (next == t) break;
      t = next;
      if (t > limit) break;
    }
    if (t > limit) {
      r.bounded = false;
      r.schedulable = false;
      r.busy_period = Duration{t};
      r.response = kMaxSimTime;
      r.response_original = kMaxSimTime;
      continue;
    }
    r.busy_period = Duration{t};
    r.instances = static_cast<std::size_t>(ceil_div(t + sm.jitter.count(), sm.period.count()));
    std::int64_t worst = 0;
    for (std::size_t q = 0; q < r.instances; ++q) {
      // Queuing delay of instance q's last frame: w = B + q C_m + (C_m − F_m) + Σ_{hp} ⌈(w + J_k + τ)/T_k⌉ C_k.
      const std::int64_t base = b + static_cast<std::int64_t>(q) * c[m] + (c[m] - f[m]);
      std::int64_t w = base;
      for (;;) {
        std::int64_t next = base;
        for (std::size_t k = 0; k < streams.size(); ++k)
          if (higher(k)) next += ceil_div(w + streams[k].jitter.count() + tau, streams[k].period.count()) * c[k];
        if (next == w || next > limit) {
          w = next;
          break;
        }
        w = next;
      }
      const std::int64_t rq = sm.jitter.count() + w - static_cast<std::int64_t>(q) * sm.period.count() + f[m];
      if (q == 0) r.response_original = Duration{rq};
      worst = std::max(worst, rq);
    }
    r.response = Duration{worst};
    r.schedulable = r.response <= sm.deadline;
  }
  return out;
}

}  // namespace oneshot::engine
