/// @file loss_model_test.cpp
/// @brief Loss processes against their laws (fixed seeds, α = 0.001) and links: FIFO,
///        reordering, and losses that never move the delays (separate streams).
///
/// Bernoulli: the loss count of n packets against Binomial(n, p) (normal approximation,
/// |z| < 3.29). Gilbert–Elliott: the loss rate by batch means (100 batches of 20 000
/// packets, far longer than the chain's memory 1/(p + r)), Student t at 0.9995; the burst
/// lengths of Gilbert's model (k = 0, h = 1) against the geometric law r(1 − r)^(ℓ−1) by
/// χ², and their mean 1/r by its normal interval.
#include <gtest/gtest.h>

#include <cmath>

#include "oneshot/engine/link.hpp"
#include "oneshot/engine/loss_model.hpp"
#include "support/goodness_of_fit.hpp"

namespace oneshot::engine {
namespace {

LossModel gilbert_elliott(double p, double r, double k, double h) {
  LossModel m;
  m.kind = LossModel::Kind::kGilbertElliott;
  m.p = p;
  m.r = r;
  m.loss_good = k;
  m.loss_bad = h;
  return m;
}

TEST(LossModel, BernoulliCountIsBinomial) {
  LossModel m;
  m.kind = LossModel::Kind::kBernoulli;
  m.p = 0.1;
  LossProcess proc(m, RandomStream(5, "loss"));
  const double n = 100000;
  double lost = 0;
  for (int i = 0; i < 100000; ++i) lost += proc.next_lost() ? 1 : 0;
  EXPECT_LT(std::fabs(lost - n * m.p) / std::sqrt(n * m.p * (1 - m.p)), test::kZ);
}

/// Batch means of the loss indicator: |mean − rate| / (sd/√batches) below t_{0.9995, 99} = 3.39.
void expect_loss_rate(const LossModel& m, std::uint64_t seed) {
  LossProcess proc(m, RandomStream(seed, "loss"));
  const int batches = 100;
  const int per_batch = 20000;
  std::vector<double> means;
  for (int b = 0; b < batches; ++b) {
    double lost = 0;
    for (int i = 0; i < per_batch; ++i) lost += proc.next_lost() ? 1 : 0;
    means.push_back(lost / per_batch);
  }
  double mean = 0;
  for (double x : means) mean += x / batches;
  double ss = 0;
  for (double x : means) ss += (x - mean) * (x - mean);
  const double se = std::sqrt(ss / (batches - 1) / batches);
  EXPECT_LT(std::fabs(mean - m.loss_rate()) / se, 3.39) << m.describe() << ": measured " << mean;
}

TEST(LossModel, GilbertElliottStationaryLossRate) {
  // π_B = p/(p + r); rate = (1 − π_B) k + π_B h.
  const LossModel m = gilbert_elliott(0.02, 0.25, 0.01, 0.7);
  EXPECT_NEAR(m.loss_rate(), (0.25 * 0.01 + 0.02 * 0.7) / 0.27, 1e-15);
  expect_loss_rate(m, 3);
  expect_loss_rate(gilbert_elliott(0.05, 0.3, 0.0, 1.0), 4);
}

TEST(LossModel, GilbertBurstsAreGeometricWithMeanOneOverR) {
  const double r = 0.3;
  LossProcess proc(gilbert_elliott(0.05, r, 0.0, 1.0), RandomStream(9, "loss"));
  std::vector<double> lengths;
  int run = 0;
  for (int i = 0; i < 2'000'000; ++i) {
    if (proc.next_lost()) {
      ++run;
    } else if (run > 0) {
      lengths.push_back(run);
      run = 0;
    }
  }
  const double nb = static_cast<double>(lengths.size());
  ASSERT_GT(nb, 10000);
  double mean = 0;
  for (double l : lengths) mean += l / nb;
  const double sd = std::sqrt(1 - r) / r;  // geometric on {1, 2, …}
  EXPECT_LT(std::fabs(mean - 1 / r) / (sd / std::sqrt(nb)), test::kZ) << "mean burst " << mean;
  std::vector<double> observed(9, 0);  // ℓ = 1 … 8, and ≥ 9
  for (double l : lengths) observed[std::min<std::size_t>(static_cast<std::size_t>(l), 9) - 1] += 1;
  std::vector<double> expected(9, 0);
  double tail = 1;
  for (std::size_t l = 1; l <= 8; ++l) {
    expected[l - 1] = nb * r * std::pow(1 - r, static_cast<double>(l - 1));
    tail -= r * std::pow(1 - r, static_cast<double>(l - 1));
  }
  expected[8] = nb * tail;
  EXPECT_LT(test::chi_square(observed, expected), test::chi_square_critical(8));
}

LinkConfig uniform_link(double p_loss, bool fifo) {
  LinkConfig c;
  c.name = "test";
  c.delay.kind = DelayModel::Kind::kUniform;
  c.delay.min = from_us(100);
  c.delay.max = from_us(5000);
  c.loss.kind = p_loss > 0 ? LossModel::Kind::kBernoulli : LossModel::Kind::kNone;
  c.loss.p = p_loss;
  c.fifo = fifo;
  return c;
}

TEST(Link, FifoNeverReordersAnyDoes) {
  Link fifo(uniform_link(0, true), 3);
  Link any(uniform_link(0, false), 3);
  SimTime last_fifo{0};
  for (int i = 0; i < 2000; ++i) {
    const SimTime sent = from_us(1000) * i;  // sent every 1 ms, delays up to 5 ms
    const SimTime f = *fifo.transmit(sent);
    EXPECT_GE(f, last_fifo);
    EXPECT_GE(f, sent + from_us(100));
    last_fifo = f;
    any.transmit(sent);
  }
  EXPECT_EQ(fifo.statistics().reordered, 0U);
  EXPECT_GT(any.statistics().reordered, 200U);
}

TEST(Link, LossesNeverMoveTheDelays) {
  // Same seed, loss 0 and 30 %: every delivered message has the delay it has without loss.
  Link clean(uniform_link(0, false), 8);
  Link lossy(uniform_link(0.3, false), 8);
  std::size_t delivered = 0;
  for (int i = 0; i < 5000; ++i) {
    const SimTime sent = from_us(20'000) * i;
    const auto a = clean.transmit(sent);
    const auto b = lossy.transmit(sent);
    ASSERT_TRUE(a.has_value());
    if (b) {
      EXPECT_EQ(*a, *b) << i;
      ++delivered;
    }
  }
  EXPECT_EQ(lossy.statistics().lost + delivered, 5000U);
  EXPECT_LT(std::fabs(static_cast<double>(lossy.statistics().lost) - 1500) / std::sqrt(5000 * 0.21), test::kZ);
}

}  // namespace
}  // namespace oneshot::engine
