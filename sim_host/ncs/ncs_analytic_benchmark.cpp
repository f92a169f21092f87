/// @file ncs_analytic_benchmark.cpp
/// @brief `ncs analytic-benchmark`: what the analytic mode costs (a benchmark, not a test):
///        the engine's covariance propagation per flow and per jump on the study's z, and an
///        analytic run beside the noise-free run it rides on.
#include <chrono>
#include <cstdint>
#include <vector>

#include "ncs_analytic.hpp"

namespace oneshot::ncs {

nlohmann::json analytic_benchmark(const Context& ctx, std::uint64_t seed) {
  using Clock = std::chrono::steady_clock;
  const auto seconds = [](Clock::time_point a) { return std::chrono::duration<double>(Clock::now() - a).count(); };
  Scenario sc = default_scenarios()[3];  // a0.5-T2-d14-s4
  sc.duration_s = 20;
  // Engine: flows over 64 interval lengths (cached after the first) and dense jumps.
  const auto pc = plant_config(ctx, sc, true);
  AnalyticTracker::Jlc jl(engine::JumpLinearPlant<kN, kM>{pc.a, pc.b, pc.qc, pc.q1c, pc.q2c});
  AnalyticTracker::Map e = AnalyticTracker::Map::identity();
  for (std::size_t j = 0; j < kZ; ++j) e(kZmem, j) = 0.1 * static_cast<double>(j % 3);
  Matrix<double, kZ, kP> f;
  f(kZy, 0) = 1;
  f(kZy + 1, 1) = 1;
  const Matrix<double, kP, kP> r = Matrix<double, kP, kP>::identity() * 1e-4;
  const std::size_t n = 200000;
  for (std::int64_t d = 0; d < 64; ++d) jl.flow(engine::from_us(1000 + d));  // fill the cache
  auto t0 = Clock::now();
  for (std::size_t i = 0; i < n; ++i) jl.flow(engine::from_us(1000 + static_cast<std::int64_t>(i % 64)));
  const double flow_ns = seconds(t0) / static_cast<double>(n) * 1e9;
  t0 = Clock::now();
  for (std::size_t i = 0; i < n; ++i) jl.jump(e, f, AnalyticTracker::Z{}, r);
  const double jump_ns = seconds(t0) / static_cast<double>(n) * 1e9;
  // Runs: AK, the noise-free simulation alone and with the tracker.
  RunOptions nf;
  nf.noise_free = true;
  RunOptions an;
  an.analytic = true;
  const int runs = 20;
  double plain = 0;
  double analytic = 0;
  double sink = 0;
  for (int k = 0; k < runs; ++k) {
    t0 = Clock::now();
    sink += run(ctx, Approach::kAK, sc, seed + static_cast<std::uint64_t>(k), nf).cost;
    plain += seconds(t0);
    t0 = Clock::now();
    sink += run(ctx, Approach::kAK, sc, seed + static_cast<std::uint64_t>(k), an).analytic.total();
    analytic += seconds(t0);
  }
  return {{"experiment", "analytic-benchmark"},
          {"z_size", kZ},
          {"flow_ns_per_event", flow_ns},
          {"jump_ns_per_event", jump_ns},
          {"scenario", sc.name},
          {"approach", "AK"},
          {"runs", runs},
          {"noise_free_run_ms", plain / runs * 1e3},
          {"analytic_run_ms", analytic / runs * 1e3},
          {"checksum", sink}};
}

}  // namespace oneshot::ncs
