/// @file ncs_live_nodes.hpp
/// @brief The pieces the live processes and the replay build identically: the controller's
///        estimator of an actuation-synchronized approach, the plant-link wire format, and
///        the CSV log writer.
#pragma once

#include <cstdint>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <string>

#include "ncs_live.hpp"
#include "ncs_loop.hpp"
#include "oneshot/node/sync_estimators.hpp"
#include "oneshot/plant_structure.hpp"

namespace oneshot::ncs::live {

using Structure = DenseStructure<kN, kM, kP>;
using Ref = SetpointReference;
using InputVec = Vector<double, kM>;
using OutputVec = Vector<double, kP>;
using HalfEst = node::HalfKalmanEstimator<Fmt, Structure, Disc>;
using Pred = node::SampledStatePredictor<Fmt, Structure, Disc>;

/// Calls fn(estimator, late_us) with the controller estimator of approach `a` (A, AK, AKx,
/// AKl, as in ncs_loop.cpp); `design` and `disc` must outlive the estimator.
template <typename Fn>
void with_sync_estimator(const Context& ctx, const Scenario& sc, Approach a, const Design& design, const Disc& disc,
                         Fn&& fn) {
  const Vector<double, kN> x0 = reference(ctx, sc).state(0);
  const auto half = [&](NoiseModel noise) {
    HalfEst e(design, disc, noise);
    e.reset(x0, design.p0, InputVec{});
    return e;
  };
  switch (a) {
    case Approach::kA: fn(Pred(disc), std::int32_t{0}); return;
    case Approach::kAK: fn(half(NoiseModel::kConstant), std::int32_t{0}); return;
    case Approach::kAKx: fn(half(NoiseModel::kExact), std::int32_t{0}); return;
    case Approach::kAKl: fn(half(NoiseModel::kConstant), ctx.worst_chain_us(sc)); return;
    default:
      throw std::invalid_argument(std::string("ncs live: approach ") + name(a) +
                                  " is not actuation-synchronized (A, AK, AKx, AKl)");
  }
}

/// The actuator's range [lo, hi] of the design, per input.
struct InputRange {
  InputVec lo;  ///< u_min.
  InputVec hi;  ///< u_max.
};

/// The actuator's range [u_min, u_max] from the design.
inline InputRange actuator_range(const Context& ctx) {
  InputRange r;
  for (std::size_t j = 0; j < kM; ++j) {
    r.lo[j] = ctx.design().u_min[j];
    r.hi[j] = ctx.design().u_max[j];
  }
  return r;
}

/// Frame checks of the live sensor (docs/node_validation.md), the same in the process and
/// the replay: requests from the actuator only, echoes in its range, t_k at most four
/// periods ahead of the sensor's clock.
template <typename Sensor>
void check_requests(const Context& ctx, Sensor& sensor) {
  const InputRange u = actuator_range(ctx);
  sensor.expect_source(kLiveActuator);
  sensor.set_echo_range(u.lo, u.hi);
  sensor.set_stamp_window(4 * ctx.period_us());
}

/// Frame checks of the live controller: reports from the sensor only, echoes in the
/// actuator's range, τ in [0, h]. Samples are only checked finite (the live plant's output
/// is not clamped to the ADC range). Periods without a report are predicted over (h set).
template <typename Controller>
void check_reports(const Context& ctx, Controller& ctrl) {
  ctrl.expect_source(kLiveSensor);
  ctrl.check_echo_range();
  ctrl.set_tau_range(0, ctx.period_us());
  ctrl.set_period_us(ctx.period_us());
}

/// Frame checks of the live actuator: commands from the controller (at `controller`) only,
/// in its range.
template <typename Actuator>
void check_commands(const Context& ctx, Actuator& act, std::uint8_t controller = kLiveController) {
  const InputRange u = actuator_range(ctx);
  act.expect_source(controller);
  act.set_command_range(u.lo, u.hi);
}

/// Logs a node's refusal counters as two records: "refused" (non-finite, out of range,
/// source) and "refused_seq" (sequence, re-acquired, stale).
template <typename Log, typename Stats>
void log_refusals(Log& log, std::int64_t t_ns, const Stats& s, std::uint32_t stale) {
  log.write("refused", t_ns, 0, 0, 0, 0, s.refused_non_finite, s.refused_out_of_range, s.refused_source);
  log.write("refused_seq", t_ns, 0, 0, 0, 0, s.refused_sequence, s.reacquired, stale);
}

/// Plant link (direct, not through the relay): sampling request 'S' k clock_us (9 bytes),
/// its answer 'Y' k y1 y2 (21 bytes), command 'U' k clock_us u (17 bytes); little-endian
/// integers, doubles in host order (one machine).
inline constexpr std::size_t kSampleRequestBytes = 9;
inline constexpr std::size_t kSampleAnswerBytes = 5 + 8 * kP;
inline constexpr std::size_t kCommandBytes = 9 + 8 * kM;

/// Little-endian 32-bit integer at `p`.
inline std::uint32_t get_u32(const std::uint8_t* p) {
  return static_cast<std::uint32_t>(p[0]) | static_cast<std::uint32_t>(p[1]) << 8 | static_cast<std::uint32_t>(p[2]) << 16 |
         static_cast<std::uint32_t>(p[3]) << 24;
}
/// Writes v little-endian at `p`.
inline void put_u32(std::uint8_t* p, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) p[i] = static_cast<std::uint8_t>(v >> (8 * i));
}

/// Node clock (µs, wrapping) at t_ns ≥ 0 since t0: floor(t / 1 µs).
inline std::uint32_t clock_us(std::int64_t t_ns) { return static_cast<std::uint32_t>(static_cast<std::uint64_t>(t_ns / 1000)); }

/// One process's CSV log (see ncs_live.hpp).
class LogWriter {
 public:
  /// Creates DIR/<role>.csv; std::runtime_error when it cannot.
  LogWriter(const std::string& dir, const std::string& role) {
    const std::string path = dir + "/" + role + ".csv";
    f_ = std::fopen(path.c_str(), "w");
    if (f_ == nullptr) throw std::runtime_error(path + ": cannot write the log");
    std::fputs("event,t_ns,clock_us,src,dst,k,v0,v1,v2\n", f_);
  }
  ~LogWriter() {
    if (f_ != nullptr) std::fclose(f_);
  }
  LogWriter(const LogWriter&) = delete;
  LogWriter& operator=(const LogWriter&) = delete;
  /// One record.
  void write(const char* event, std::int64_t t_ns, std::uint32_t clock, int src, int dst, std::uint32_t k, double v0 = 0,
             double v1 = 0, double v2 = 0) {
    std::fprintf(f_, "%s,%lld,%u,%d,%d,%u,%.17g,%.17g,%.17g\n", event, static_cast<long long>(t_ns), clock, src, dst, k, v0,
                 v1, v2);
  }
  /// Flushes to the file.
  void flush() { std::fflush(f_); }

 private:
  std::FILE* f_ = nullptr;
};

}  // namespace oneshot::ncs::live
