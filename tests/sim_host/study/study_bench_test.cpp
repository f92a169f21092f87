/// @file study_bench_test.cpp
/// @brief `study bench`'s mean over an approach's runs (mean_of(), study_bench.hpp) against its
///        closed form on a sweep of known values.
#include <gtest/gtest.h>

#include <cstddef>
#include <stdexcept>

#include "oneshot/engine/sweep.hpp"
#include "study_bench.hpp"

namespace oneshot::study {
namespace {

TEST(StudyBench, MeanOfAveragesAnApproachsRunsOverScenariosAndSeeds) {
  // 2 approaches × 3 scenarios × 4 seeds, metrics "cost" = 100 a + 10 x + k and "events" = −2 cost:
  // the mean of approach a is 100 a + 10 · 1 + 1.5 (x over 0, 1, 2; k over 0 … 3), and −2 times
  // that (sums of small integers and their division by 12: exact, measured 0).
  engine::SweepResults r;
  r.spec.approaches = {"I", "S"};
  r.spec.scenarios = {"x0", "x1", "x2"};
  r.spec.seeds = 4;
  r.spec.metrics = {"cost", "events"};
  r.values.assign(r.spec.runs() * r.spec.metrics.size(), 0);
  r.done.assign(r.spec.runs(), 1);
  for (std::size_t a = 0; a < 2; ++a)
    for (std::size_t x = 0; x < 3; ++x)
      for (std::size_t k = 0; k < 4; ++k) {
        const std::size_t run = r.spec.run_index(a, x, k);
        const double cost = 100.0 * static_cast<double>(a) + 10.0 * static_cast<double>(x) + static_cast<double>(k);
        r.values[run * 2] = cost;
        r.values[run * 2 + 1] = -2 * cost;
      }
  for (std::size_t a = 0; a < 2; ++a) {
    const double expected = 100.0 * static_cast<double>(a) + 10.0 + 1.5;
    EXPECT_EQ(mean_of(r, a, "cost"), expected) << a;
    EXPECT_EQ(mean_of(r, a, "events"), -2 * expected) << a;
  }
  EXPECT_THROW(static_cast<void>(mean_of(r, 0, "nope")), std::invalid_argument);  // an unknown metric
}

}  // namespace
}  // namespace oneshot::study
