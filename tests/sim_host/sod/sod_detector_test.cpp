/// @file sod_detector_test.cpp
/// @brief The dropout detector and the receiver's R̄: d never exceeds the true number of
///        consecutive losses (10⁶ steps at ξ = 0.2), and R̄ follows its closed form.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "oneshot/engine/loss_model.hpp"
#include "oneshot/engine/random_stream.hpp"
#include "oneshot/node/dropout_detector.hpp"
#include "oneshot/node/held_measurement.hpp"
#include "oneshot/node/send_on_delta_trigger.hpp"

namespace {

using oneshot::node::SendCause;

TEST(SodDetector, NeverExceedsTheTrueConsecutiveLossesOverAMillionSteps) {
  // One modified-SOD node on a random walk (sd 0.05 per step, δy = 0.5, n_t = 50): a mix of
  // (2a) and (2b) sends; Bernoulli losses ξ = 0.2 from the link's own stream.
  oneshot::Vector<double, 1> dy;
  dy[0] = 0.5;
  const std::uint32_t n_t = 50;
  oneshot::node::SendOnDeltaTrigger<double, 1> trig(dy, n_t);
  oneshot::node::DropoutDetector det(n_t);
  oneshot::engine::LossModel lm;
  lm.kind = oneshot::engine::LossModel::Kind::kBernoulli;
  lm.p = 0.2;
  oneshot::engine::LossProcess loss(lm, oneshot::engine::RandomStream(3, "link/node1/loss"));
  oneshot::engine::RandomStream walk(3, "walk");
  oneshot::Vector<double, 1> y;
  std::uint64_t violations = 0, lost = 0, detected = 0, time_sends = 0, delta_sends = 0, silent_detected_steps = 0;
  std::uint32_t run = 0, last_d = 0;  // packets sent since the last arrival (all lost); d at the previous step
  for (std::uint32_t k = 0; k < 1'000'000; ++k) {
    y[0] += 0.05 * walk.normal();
    const SendCause cause = trig.evaluate(k, y);
    bool arrived = false;
    if (cause != SendCause::kNone) {
      trig.on_sent(k, y);
      time_sends += cause == SendCause::kTime;
      delta_sends += cause == SendCause::kDelta;
      if (loss.next_lost()) {
        ++lost;
        ++run;
      } else {
        det.on_receive(k);
        arrived = true;
        run = 0;
      }
    }
    if (arrived) {
      last_d = 0;
      continue;
    }
    const std::uint32_t d = det.dropouts(k);
    if (d > run) ++violations;
    if (d > last_d) detected += d - last_d;
    if (d > 0) ++silent_detected_steps;
    last_d = d;
  }
  EXPECT_EQ(violations, 0u);
  EXPECT_LE(detected, lost);
  // The run is not trivial: both rules fire and most losses are seen.
  EXPECT_GT(time_sends, 1000u);
  EXPECT_GT(delta_sends, 1000u);
  EXPECT_GT(detected, lost / 2);
  EXPECT_GT(silent_detected_steps, 0u);
}

TEST(SodDetector, PlainSodDetectsNothingAndWrapsSafely) {
  oneshot::node::DropoutDetector plain(0);
  plain.on_receive(5);
  EXPECT_EQ(plain.dropouts(100000), 0u);
  oneshot::node::DropoutDetector det(10);
  EXPECT_EQ(det.dropouts(1000), 0u);  // nothing received yet
  det.on_receive(0xFFFFFFF0u);
  EXPECT_EQ(det.dropouts(0xFFFFFFF0u + 9u), 0u);
  EXPECT_EQ(det.dropouts(0xFFFFFFF0u + 10u), 1u);
  EXPECT_EQ(det.dropouts(0xFFFFFFF0u + 35u), 3u);  // across the wrap of the sequence number
}

TEST(SodDetector, ReceiverBuildsHeldVarianceInClosedForm) {
  oneshot::Vector<double, 2> dy, r;
  dy[0] = 0.5;
  dy[1] = 0.25;
  r[0] = 0.01;
  r[1] = 0.02;
  const std::uint32_t n_t[2] = {10, 0};
  oneshot::node::HeldMeasurementReceiver<double, 2> rx(dy, r, n_t, oneshot::node::SilencePolicy::kHeld);
  EXPECT_FALSE(rx.measurement(0, 0).present);  // nothing to hold yet
  EXPECT_EQ(rx.on_packet(0, 3, std::numeric_limits<double>::quiet_NaN()), oneshot::node::FrameStatus::kRefusedNonFinite);  // refused, counted
  EXPECT_FALSE(rx.measurement(0, 3).present);
  EXPECT_EQ(rx.refusals().refused_non_finite, 1U);
  EXPECT_EQ(rx.on_packet(0, 3, 1.5), oneshot::node::FrameStatus::kOk);
  EXPECT_EQ(rx.on_packet(1, 3, -2.0), oneshot::node::FrameStatus::kOk);
  auto m = rx.measurement(0, 3);
  EXPECT_TRUE(m.present && m.arrived);
  EXPECT_EQ(m.z, 1.5);
  EXPECT_EQ(m.r_bar, 0.01);
  for (std::uint32_t k = 4; k < 40; ++k) {
    m = rx.measurement(0, k);
    const std::uint32_t d = (k - 3) / 10;
    EXPECT_EQ(m.dropouts, d);
    EXPECT_TRUE(m.present && !m.arrived);
    EXPECT_EQ(m.z, 1.5);
    EXPECT_NEAR(m.r_bar, 0.01 + std::pow((d + 1) * 0.5, 2) / 3, 1e-15);
    const auto m1 = rx.measurement(1, k);  // plain SOD node: d ≡ 0
    EXPECT_EQ(m1.dropouts, 0u);
    EXPECT_NEAR(m1.r_bar, 0.02 + 0.25 * 0.25 / 3, 1e-15);
  }
  oneshot::node::HeldMeasurementReceiver<double, 2> kf(dy, r, n_t, oneshot::node::SilencePolicy::kPredictOnly);
  ASSERT_EQ(kf.on_packet(0, 3, 1.5), oneshot::node::FrameStatus::kOk);
  EXPECT_TRUE(kf.measurement(0, 3).present);
  EXPECT_FALSE(kf.measurement(0, 4).present);
}

}  // namespace
