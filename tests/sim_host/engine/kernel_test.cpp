/// @file kernel_test.cpp
/// @brief The event kernel: the total order of simultaneous events, causality, and
///        determinism of a randomly growing event graph.
#include <gtest/gtest.h>

#include <tuple>
#include <vector>

#include "oneshot/engine/kernel.hpp"

namespace oneshot::engine {
namespace {

struct Logged {
  std::int64_t t;
  EventClass cls;
  std::uint64_t arg;
  bool operator==(const Logged& o) const { return t == o.t && cls == o.cls && arg == o.arg; }
};

TEST(Kernel, SimultaneousEventsRunByClassThenInsertion) {
  Kernel k(1);
  std::vector<Logged> log;
  const HandlerId h = k.add_handler("log", [&](std::uint64_t a) { log.push_back({k.now().count(), k.current_class(), a}); });
  // Scheduled out of order: time 5 before time 3; classes mixed at each time.
  k.schedule(Duration{5}, EventClass::kCompute, h, 1);
  k.schedule(Duration{3}, EventClass::kRecord, h, 2);
  k.schedule(Duration{3}, EventClass::kActuation, h, 3);
  k.schedule(Duration{3}, EventClass::kSample, h, 4);
  k.schedule(Duration{3}, EventClass::kActuation, h, 5);
  k.schedule(Duration{5}, EventClass::kPlantStep, h, 6);
  k.schedule(Duration{3}, EventClass::kEnvironment, h, 7);
  EXPECT_EQ(k.run_until(Duration{10}), 7U);
  const std::vector<std::uint64_t> expected = {7, 3, 5, 4, 2, 6, 1};
  ASSERT_EQ(log.size(), expected.size());
  for (std::size_t i = 0; i < log.size(); ++i) EXPECT_EQ(log[i].arg, expected[i]) << i;
}

TEST(Kernel, AnEarlierClassScheduledNowRunsRightAfterTheCurrentHandler) {
  Kernel k(1);
  std::vector<std::uint64_t> log;
  HandlerId h = 0;
  h = k.add_handler("log", [&](std::uint64_t a) {
    log.push_back(a);
    if (a == 1) k.schedule(k.now(), EventClass::kDelivery, h, 9);  // zero-delay message from a computation
  });
  k.schedule(Duration{4}, EventClass::kCompute, h, 1);
  k.schedule(Duration{4}, EventClass::kCompute, h, 2);
  k.run_until(Duration{4});
  EXPECT_EQ(log, (std::vector<std::uint64_t>{1, 9, 2}));
}

TEST(Kernel, TimeNeverGoesBack) {
  Kernel k(1);
  const HandlerId h = k.add_handler("noop", [](std::uint64_t) {});
  k.schedule(Duration{10}, EventClass::kCompute, h);
  k.run_until(Duration{10});
  EXPECT_THROW(k.schedule(Duration{9}, EventClass::kCompute, h), std::logic_error);
  EXPECT_THROW(k.schedule(kMaxSimTime + Duration{1}, EventClass::kCompute, h), std::logic_error);
  EXPECT_THROW(k.schedule(Duration{11}, EventClass::kCompute, 99), std::logic_error);
  EXPECT_NO_THROW(k.schedule(Duration{10}, EventClass::kCompute, h));
}

/// A random event graph: each event schedules 0–3 more (a growing branching process,
/// capped at 5000 events), at delays of 0–2 ns (many ties) and random classes, drawn from
/// the run's stream.
std::vector<Logged> random_graph(std::uint64_t seed) {
  Kernel k(seed);
  RandomStream rng = k.stream("graph");
  std::vector<Logged> log;
  HandlerId h = 0;
  std::uint64_t next_arg = 100;
  h = k.add_handler("node", [&](std::uint64_t a) {
    log.push_back({k.now().count(), k.current_class(), a});
    const auto children = rng.uniform_int(0, 3);
    for (std::int64_t c = 0; c < children && log.size() < 5000; ++c) {
      const auto cls = static_cast<EventClass>(rng.uniform_int(0, 9));
      k.schedule_in(Duration{rng.uniform_int(0, 2)}, cls, h, next_arg++);
    }
  });
  for (std::uint64_t a = 0; a < 20; ++a) k.schedule(Duration{static_cast<std::int64_t>(a % 3)}, static_cast<EventClass>(a % 10), h, a);
  k.run_until(Duration{1'000'000});
  return log;
}

TEST(Kernel, SameSeedSameEventOrderDifferentSeedDifferent) {
  const auto a = random_graph(7);
  const auto b = random_graph(7);
  const auto c = random_graph(8);
  ASSERT_GT(a.size(), 500U);
  EXPECT_EQ(a, b);
  EXPECT_FALSE(a == c);
  for (std::size_t i = 1; i < a.size(); ++i) EXPECT_GE(a[i].t, a[i - 1].t) << i;
}

TEST(SimTime, NodeClocksWrapAndFloorToMicroseconds) {
  EXPECT_EQ(node_instant<std::uint32_t>(Duration{1'999}).ticks(), 1U);
  EXPECT_EQ(node_instant<std::uint32_t>(Duration{0}, Duration{-1}).ticks(), 0xFFFFFFFFU);
  // 2^32 µs later the 32-bit counter reads the same, the 64-bit one does not.
  const Duration wrap{(std::int64_t{1} << 32) * 1000};
  EXPECT_EQ(node_instant<std::uint32_t>(wrap + Duration{5000}).ticks(), 5U);
  EXPECT_EQ(node_instant<std::uint64_t>(wrap + Duration{5000}).ticks(), (std::uint64_t{1} << 32) + 5);
  EXPECT_THROW(from_seconds(-1, "t"), std::invalid_argument);
  EXPECT_THROW(from_seconds(1e300, "t"), std::invalid_argument);
  EXPECT_EQ(from_seconds(0.05, "t"), Duration{50'000'000});
}

}  // namespace
}  // namespace oneshot::engine
