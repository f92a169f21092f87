/// @file pipeline_test.cpp
/// @brief The arrival law and the pipeline that realizes it; the closed loop's basics.
#include <gtest/gtest.h>

#include <cmath>

#include "closed_loop.hpp"
#include "dropping_plant.hpp"

namespace oneshot::dropping {
namespace {

TEST(Arrival, ClosedForm) {
  EXPECT_NEAR(arrival_probability(1, 1.0, 0.01), 0.99 * std::exp(-1.0), 1e-15);
  EXPECT_NEAR(arrival_probability(2, 2.0, 0.0), std::exp(-2.0) * 3, 1e-15);
  EXPECT_NEAR(arrival_probability(60, 3.0, 0.01), 0.99, 1e-12);
  EXPECT_NEAR(delay_for_lambda(0.99 * std::exp(-1.0), 0.01), 1.0, 1e-14);
  EXPECT_THROW(static_cast<void>(arrival_probability(0, 1, 0.01)), std::invalid_argument);
  EXPECT_THROW(static_cast<void>(delay_for_lambda(0.995, 0.01)), std::invalid_argument);
}

TEST(Arrival, PipelineRealizesTheLaw) {
  // 40 000 stamps per cell: the frequency is within 4.5 binomial standard deviations.
  for (double d : {0.5, 2.0})
    for (int t : {1, 3, 6}) {
      const std::size_t steps = 40000;
      const double lam = arrival_probability(t, d, 0.01);
      const double f = simulate_gamma_frequency(t, d, 0.01, steps, 5);
      const double sd = std::sqrt(lam * (1 - lam) / static_cast<double>(steps - static_cast<std::size_t>(t)));
      EXPECT_NEAR(f, lam, 4.5 * sd) << "D " << d << " T_hold " << t;
    }
}

TEST(ClosedLoop, BufferedRunIsDeterministicAndSane) {
  const DroppingPlant p = load_dropping_plant("");
  RunConfig c;
  c.t_hold = 2;
  c.mean_delay_periods = 1;
  c.steps = 400;
  const RunMetrics a = run_closed_loop(p, c, 3), b = run_closed_loop(p, c, 3);
  EXPECT_EQ(a.err, b.err);
  EXPECT_EQ(a.trace_p, b.trace_p);
  EXPECT_FALSE(a.failed);
  EXPECT_GT(a.gamma, 0.5);
  EXPECT_LT(a.gamma, 1.0);
  EXPECT_GT(a.reordered, 0);
  // Anchor estimates are filtered (T_hold behind), so smaller covariance than the current prediction.
  EXPECT_LT(a.trace_p_anchor, a.trace_p);
  c.t_hold = 9;
  EXPECT_THROW(static_cast<void>(run_closed_loop(p, c, 3)), std::invalid_argument);
}

TEST(ClosedLoop, NoiseFreeLinkWithAllPacketsGivesTheBernoulliOneFilter) {
  // λ = 1 Bernoulli channel with T_hold = 1 and a network with D → 0, no loss: both deliver
  // every packet half a period later, so the estimators see the same data.
  const DroppingPlant p = load_dropping_plant("");
  RunConfig net;
  net.mean_delay_periods = 1e-12;
  net.loss = 0;
  net.steps = 300;
  RunConfig ber = net;
  ber.channel = ChannelKind::kBernoulli;
  ber.bernoulli_lambda = 1.0;
  const RunMetrics a = run_closed_loop(p, net, 4), b = run_closed_loop(p, ber, 4);
  EXPECT_EQ(a.gamma, 1.0);
  EXPECT_EQ(b.gamma, 1.0);
  EXPECT_NEAR(a.err, b.err, 1e-12 * b.err);
  EXPECT_NEAR(a.trace_p, b.trace_p, 1e-12 * b.trace_p);
}

}  // namespace
}  // namespace oneshot::dropping
