/// @file study_shared_caches_test.cpp
/// @brief The sweep's shared plant caches (ncs::ShapeCachePools) on every plant shape: the
///        pools memoize pure functions of (plant, interval length), so a sweep with them gives
///        the same bytes, per seed and in its summary, as each run with its own caches — on
///        the cart-pole-like plant (4, 1, 4) of examples/cart_pole_inline.json, a first-order
///        plant (1, 1, 1), and the several-loop runs of examples/two_loops_can.json with one
///        loop of each shape. The oracle is the run without the pool (exact equality: the
///        cached maps are the bytes the run would compute).
#include <gtest/gtest.h>

#include <cstring>
#include <string>

#include "ncs_cache_pools.hpp"
#include "ncs_loop.hpp"
#include "oneshot/engine/study_file.hpp"
#include "study_check.hpp"
#include "study_example.hpp"
#include "study_ncs_runner.hpp"
#include "study_ncs_sweep.hpp"
#include "support/temp_files.hpp"

namespace oneshot::study {
namespace {

const test_support::StudyExample kCachesCartPole("cart_pole_inline.json");
const test_support::StudyExample kCachesLoops("two_loops_can.json");

/// cart_pole_inline.json with a first-order plant inline: ẋ = −4 x + 8 u, y = x (Q1c = 25,
/// Q2c = 1, Q_c = 4e−6, R = 8e−5; one ADC channel): shape (1, 1, 1).
void scalar_plant(nlohmann::json& j) {
  nlohmann::json& c = j["plant"]["continuous"];
  c["states"] = {"x"};
  c["outputs"] = {"x"};
  c["tracked_outputs"] = {"x"};
  c["A"] = {{-4.0}};
  c["B"] = {{8.0}};
  c["C"] = {{1.0}};
  c["Q1c"] = {{25.0}};
  c["Q2c"] = {{1.0}};
  c["Q_c"] = {{4e-6}};
  c["measurement_covariance"] = {{8e-5}};
  c["board"]["adc_min_volts"] = {-2.5};
  c["board"]["adc_max_volts"] = {2.5};
}

/// The shard (every run's metrics, per seed) and the summary of a sweep of `s`, 3 seeds.
std::string caches_sweep_bytes(const NcsStudy& s, unsigned threads, bool shared, const std::string& dir) {
  const engine::SweepResults r = run_ncs_sweep(s, 3, threads, engine::Shard{}, false, shared);
  const std::string out = test::fresh_dir("oneshot_shared_caches_test", dir);
  const nlohmann::json summary = s.loops.empty() ? run_outputs(r, out, false) : loops_outputs(r, out, false);
  return engine::shard_to_json(r).dump() + summary.dump();
}

/// Sweeps with the pool (1 and 2 threads) against each run with its own caches.
void expect_same_bytes_with_and_without_pools(const NcsStudy& s, const std::string& name) {
  const std::string own = caches_sweep_bytes(s, 1, false, name + "_own");
  EXPECT_EQ(caches_sweep_bytes(s, 1, true, name + "_shared1"), own) << name;
  EXPECT_EQ(caches_sweep_bytes(s, 2, true, name + "_shared2"), own) << name;
}

TEST(ShapeCachePools, EachListedShapeHasItsOwnPoolAndAnotherShapeNone) {
  ncs::ShapeCachePools pools;
  using Scalar = ncs::Shape<1, 1, 1>;
  using CartPole = ncs::Shape<4, 1, 4>;
  using Unlisted = ncs::Shape<9, 3, 7>;
  EXPECT_NE(pools.pool<ncs::BoardShape>(), nullptr);
  EXPECT_NE(pools.pool<Scalar>(), nullptr);
  EXPECT_NE(pools.pool<CartPole>(), nullptr);
  EXPECT_EQ(pools.pool<Unlisted>(), nullptr);  // not in ONESHOT_NCS_SHAPES: a run keeps its own caches
  EXPECT_EQ(pools.size(), 0U);
}

TEST(ShapeCachePools, ARunOfAnotherShapeTakesItsCachesFromItsShapesPool) {
  // S on the cart-pole-like plant: its plant events at ever different offsets (delays, τ_c).
  const NcsStudy s = kCachesCartPole.study([](nlohmann::json&) {}, 1.0);
  ASSERT_EQ(s.ctx->plant().a.rows, 4U);
  ncs::ShapeCachePools pools;
  ncs::RunOptions with;
  with.caches = &pools;
  for (const std::uint64_t seed : {1U, 2U}) {  // the second run meets the first's lengths again
    const ncs::RunResult own = ncs::run(*s.ctx, ncs::Approach::kS, s.scenarios[0], seed, {});
    const ncs::RunResult shared = ncs::run(*s.ctx, ncs::Approach::kS, s.scenarios[0], seed, with);
    EXPECT_EQ(std::memcmp(&own.cost, &shared.cost, sizeof own.cost), 0) << seed;  // bit for bit
    EXPECT_EQ(own.events, shared.events) << seed;
  }
  // One plant with noise: its interval maps and its noise terms, in the (4, 1, 4) pool only.
  using CartPole = ncs::Shape<4, 1, 4>;
  EXPECT_EQ(pools.pool<CartPole>()->size(), 2U);
  EXPECT_EQ(pools.size(), 2U);
}

TEST(ShapeCachePools, TwoPlantsInOneShapesPoolKeepTheirOwnRuns) {
  // The first-order plant embedded in (4, 1, 4) (zero padded) and the cart-pole-like plant of
  // that shape, alternately on one pool: the pool's keys are the (padded) matrices' bytes, so
  // neither takes the other's maps; each run is its own-cache run, bit for bit.
  const NcsStudy cart_pole = kCachesCartPole.study([](nlohmann::json&) {}, 1.0);
  const NcsStudy scalar = kCachesCartPole.study(scalar_plant, 1.0);
  ncs::ShapeCachePools pools;
  ncs::RunOptions with;
  with.caches = &pools;
  ncs::RunOptions padded_own;
  padded_own.force_shape = ncs::NcsShapeOf{4, 1, 4, true};
  ncs::RunOptions padded_with = padded_own;
  padded_with.caches = &pools;
  for (const std::uint64_t seed : {1U, 2U}) {
    for (const ncs::Approach a : {ncs::Approach::kS, ncs::Approach::kSK}) {
      const ncs::RunResult c_own = ncs::run(*cart_pole.ctx, a, cart_pole.scenarios[0], seed, {});
      const ncs::RunResult s_own = ncs::run(*scalar.ctx, a, scalar.scenarios[0], seed, padded_own);
      const ncs::RunResult c_shared = ncs::run(*cart_pole.ctx, a, cart_pole.scenarios[0], seed, with);
      const ncs::RunResult s_shared = ncs::run(*scalar.ctx, a, scalar.scenarios[0], seed, padded_with);
      EXPECT_EQ(std::memcmp(&c_own.cost, &c_shared.cost, sizeof c_own.cost), 0) << seed;
      EXPECT_EQ(std::memcmp(&s_own.cost, &s_shared.cost, sizeof s_own.cost), 0) << seed;
      EXPECT_NE(c_own.cost, s_own.cost);  // two plants, not one run twice
    }
  }
  using CartPole = ncs::Shape<4, 1, 4>;
  EXPECT_EQ(pools.pool<CartPole>()->size(), 4U);  // each plant's interval maps and noise terms
}

TEST(ShapeCachePools, SweepsOfEveryShapeGiveTheSameBytesWithAndWithoutThePools) {
  // 3 s: past the set-point's first switch (T_r / 2 = 2 s), so I's cost (the ratios' base) is not 0.
  const NcsStudy cart_pole = kCachesCartPole.study([](nlohmann::json&) {}, 3.0);
  ASSERT_EQ(cart_pole.ctx->plant().a.rows, 4U);
  expect_same_bytes_with_and_without_pools(cart_pole, "cart_pole");
  const NcsStudy scalar = kCachesCartPole.study(scalar_plant, 3.0);
  ASSERT_EQ(scalar.ctx->plant().a.rows, 1U);
  expect_same_bytes_with_and_without_pools(scalar, "scalar_plant");
}

TEST(ShapeCachePools, SeveralLoopsOfTwoShapesGiveTheSameBytesWithAndWithoutThePools) {
  // two_loops_can.json with the servo loop's plant the cart-pole-like one (its period is the
  // servo's, 20 ms) on point-to-point legs U[0.5, 2] ms (the bus takes the board's frames
  // only): a board loop (2, 1, 2) on the bus and a (4, 1, 4) loop in one engine run, and each
  // loop alone (run_loops_sweep()).
  nlohmann::json j = kCachesLoops.json();
  j["loops"][1]["plant"] = kCachesCartPole.json()["plant"];
  for (nlohmann::json& l : j["links"]) {
    if (l["name"] != "servo_sc" && l["name"] != "servo_ca") continue;
    l = {{"name", l["name"]}, {"from", l["from"]}, {"to", l["to"]},
         {"delay", {{"model", "uniform"}, {"min_us", 500}, {"max_us", 2000}, {"resolution_us", 1}}}, {"order", "fifo"}};
  }
  const engine::StudyFile f = kCachesLoops.parse(j);
  NcsStudy s = map_ncs_study(f);
  cap_duration(s, 3.0, "test");
  attach_bus_bounds(s, resolve_study(f));
  ASSERT_EQ(s.loops.size(), 2U);
  ASSERT_EQ(s.loops[1].ctx->plant().a.rows, 4U);
  expect_same_bytes_with_and_without_pools(s, "two_loops");
}

}  // namespace
}  // namespace oneshot::study
