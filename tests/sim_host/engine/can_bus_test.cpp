/// @file can_bus_test.cpp
/// @brief The CAN bus against the response-time analysis of Davis, Burns, Bril & Lukkien
///        (Real-Time Systems 2007): frame lengths, simulated worst cases never above the
///        analytic bound, the paper's counter-example to the original analysis, and deadline
///        misses where the analysis says a set is unschedulable.
#include <gtest/gtest.h>

#include <iostream>

#include "oneshot/engine/can_analysis.hpp"
#include "oneshot/engine/can_bus.hpp"
#include "oneshot/engine/can_traffic.hpp"

namespace oneshot::engine {
namespace {

TEST(CanBus, WorstCaseFrameLengths) {
  // Davis et al. eq. 1: (g + 8s + 13 + ⌊(g + 8s − 1)/4⌋) bits.
  EXPECT_EQ(can_frame_bits(8, false), 135);
  EXPECT_EQ(can_frame_bits(0, false), 55);
  EXPECT_EQ(can_frame_bits(7, false), 125);
  EXPECT_EQ(can_frame_bits(8, true), 160);
  EXPECT_EQ(can_frame_bits(0, true), 80);
  EXPECT_THROW(can_frame_bits(9, false), std::invalid_argument);
  Kernel k(1);
  EXPECT_THROW(CanBus(k, CanBusConfig{"odd", 300'000, false}), std::invalid_argument);  // 3333.3 ns per bit
  CanBus bus(k, CanBusConfig{"b", 500'000, false});
  EXPECT_EQ(bus.frame_time(8), Duration{270'000});
}

/// Simulates `streams` released from `offsets` for `horizon`; returns what was observed.
std::vector<CanTraffic::Observed> simulate(const std::vector<CanStream>& streams, const std::vector<Duration>& offsets,
                                           std::int64_t bit_rate, SimTime horizon, std::uint64_t seed) {
  Kernel k(seed);
  CanBus bus(k, CanBusConfig{"bus", bit_rate, false});
  CanTraffic traffic(k, bus, streams, offsets, horizon);
  k.run_until(horizon + Duration{1'000'000'000});
  return traffic.observed();
}

/// The paper's example: A, B, C with 1 ms frames (7 bytes at 125 kbit/s), T = 2.5, 3.5, 3.5 ms.
std::vector<CanStream> davis_example(Duration deadline_c) {
  return {{"A", 1, 7, from_us(2500), Duration{0}, from_us(2500)},
          {"B", 2, 7, from_us(3500), Duration{0}, from_us(3500)},
          {"C", 3, 7, from_us(3500), Duration{0}, deadline_c}};
}

TEST(CanAnalysis, TheBusyPeriodFixFindsTheSecondInstanceOfTheLowestMessage) {
  const CanBusConfig cfg{"bus", 125'000, false};
  const auto bounds = can_response_times(davis_example(from_us(3500)), cfg);
  EXPECT_EQ(bounds[0].response, from_us(2000));  // blocked by one lower frame, then 1 ms
  EXPECT_EQ(bounds[2].response_original, from_us(3000));
  EXPECT_EQ(bounds[2].instances, 2U);
  EXPECT_EQ(bounds[2].response, from_us(3500));
  // Synchronous release: C's second frame waits for A, B and A again: 3.5 ms, above the
  // original analysis's 3 ms and exactly at the revised bound.
  const auto seen = simulate(davis_example(from_us(3500)), {Duration{0}, Duration{0}, Duration{0}}, 125'000,
                             from_us(100'000), 1);
  EXPECT_EQ(seen[2].worst, from_us(3500));
  EXPECT_GT(seen[2].worst, bounds[2].response_original);
  for (std::size_t i = 0; i < 3; ++i) EXPECT_LE(seen[i].worst, bounds[i].response) << i;
}

TEST(CanAnalysis, AnUnschedulableSetMissesDeadlines) {
  // With D_C = 3.4 ms the original analysis (3 ms) accepts C, the revised one (3.5 ms) does not.
  const CanBusConfig cfg{"bus", 125'000, false};
  const auto set = davis_example(from_us(3400));
  const auto bounds = can_response_times(set, cfg);
  EXPECT_LE(bounds[2].response_original, set[2].deadline);
  EXPECT_FALSE(bounds[2].schedulable);
  const auto seen = simulate(set, {Duration{0}, Duration{0}, Duration{0}}, 125'000, from_us(100'000), 1);
  EXPECT_GT(seen[2].misses, 0U);
  EXPECT_EQ(seen[0].misses + seen[1].misses, 0U);
  // Overload (utilization above 1): no bound, and misses pile up.
  std::vector<CanStream> overload = set;
  overload[2].period = from_us(1500);
  overload[2].deadline = from_us(1500);
  const auto unbounded = can_response_times(overload, cfg);
  EXPECT_FALSE(unbounded[2].bounded);
  const auto late = simulate(overload, {Duration{0}, Duration{0}, Duration{0}}, 125'000, from_us(100'000), 1);
  EXPECT_GT(late[2].misses, 10U);
}

TEST(CanAnalysis, SimulatedWorstCasesNeverExceedTheBound) {
  // Eight streams at 500 kbit/s, deadline-monotonic identifiers, jitter up to 30 % of the
  // period, utilization 0.74: random offsets and jitter draws over 5 seeds of 2 s, and one
  // synchronous release.
  const std::int64_t periods_us[] = {1000, 1500, 2000, 2500, 4000, 5000, 10000, 20000};
  const std::size_t payload[] = {8, 4, 8, 2, 8, 6, 8, 1};
  const double jitter_fraction[] = {0.1, 0.3, 0.0, 0.2, 0.25, 0.1, 0.3, 0.05};
  std::vector<CanStream> streams;
  for (std::size_t i = 0; i < 8; ++i) {
    const Duration t = from_us(periods_us[i]);
    streams.push_back({"s" + std::to_string(i), static_cast<std::uint32_t>(0x100 + i), payload[i], t,
                       Duration{static_cast<std::int64_t>(jitter_fraction[i] * static_cast<double>(t.count()))}, t});
  }
  const CanBusConfig cfg{"bus", 500'000, false};
  const auto bounds = can_response_times(streams, cfg);
  double utilization = 0;
  for (std::size_t i = 0; i < 8; ++i) {
    ASSERT_TRUE(bounds[i].bounded) << i;
    utilization += static_cast<double>(bounds[i].transmission.count()) / static_cast<double>(streams[i].period.count());
  }
  EXPECT_GT(utilization, 0.7);
  std::vector<Duration> worst(8, Duration{0});
  for (std::uint64_t seed = 0; seed <= 5; ++seed) {
    std::vector<Duration> offsets(8, Duration{0});
    RandomStream rng(seed, "offsets");
    if (seed > 0)
      for (std::size_t i = 0; i < 8; ++i) offsets[i] = Duration{rng.uniform_int(0, streams[i].period.count() - 1)};
    const auto seen = simulate(streams, offsets, cfg.bit_rate, from_us(2'000'000), seed);
    for (std::size_t i = 0; i < 8; ++i) {
      EXPECT_LE(seen[i].worst, bounds[i].response) << "stream " << i << " seed " << seed;
      EXPECT_GT(seen[i].frames, 90U);
      worst[i] = std::max(worst[i], seen[i].worst);
    }
  }
  for (std::size_t i = 0; i < 8; ++i) {
    std::cout << "[ info ] stream " << i << ": bound " << bounds[i].response.count() / 1000 << " us, simulated worst "
              << worst[i].count() / 1000 << " us (" << 100 * worst[i].count() / bounds[i].response.count() << " %)\n";
  }
}

TEST(CanBus, SharedBusDelaysComeFromTheTraffic) {
  // Two loops share a bus: the lower-priority frame queued at the same instant waits for
  // the higher one; an idle bus delivers after exactly one frame time.
  Kernel k(1);
  CanBus bus(k, CanBusConfig{"bus", 1'000'000, false});
  std::vector<std::pair<std::uint64_t, std::int64_t>> got;
  const HandlerId deliver = k.add_handler("d", [&](std::uint64_t a) { got.emplace_back(a, k.now().count()); });
  const HandlerId send = k.add_handler("s", [&](std::uint64_t a) { bus.queue(a == 1 ? 0x20 : 0x10, 8, deliver, a); });
  k.schedule(Duration{0}, EventClass::kCompute, send, 1);
  k.schedule(Duration{0}, EventClass::kCompute, send, 2);
  k.schedule(from_us(1000), EventClass::kCompute, send, 3);
  k.run_until(from_us(2000));
  ASSERT_EQ(got.size(), 3U);
  EXPECT_EQ(got[0], std::make_pair(std::uint64_t{2}, std::int64_t{135'000}));   // id 0x10 wins arbitration
  EXPECT_EQ(got[1], std::make_pair(std::uint64_t{1}, std::int64_t{270'000}));   // then 0x20, non-preempted
  EXPECT_EQ(got[2], std::make_pair(std::uint64_t{3}, std::int64_t{1'135'000})); // idle bus: one frame time
  EXPECT_EQ(bus.statistics().frames, 3U);
}

}  // namespace
}  // namespace oneshot::engine
