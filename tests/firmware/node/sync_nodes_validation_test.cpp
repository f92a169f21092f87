/// @file sync_nodes_validation_test.cpp
/// @brief The actuation-synchronized nodes refuse untrusted frames (issue 24): NaN samples
///        never reach the estimate, one forged far-future sequence number does not stop the
///        loop, a restarted actuator (k from 0) is re-acquired within R frames, and a
///        non-finite estimator result resets it to the design's x0, P0.
#include <gtest/gtest.h>

#include <cstdint>
#include <limits>

#include "oneshot/host/host_network.hpp"
#include "oneshot/node/sync_controller_node.hpp"
#include "oneshot/node/sync_estimators.hpp"
#include "oneshot/node/sync_sensor_node.hpp"
#include "oneshot/table_discretizer.hpp"
#include "sync_test_loop.hpp"

namespace oneshot::node {
namespace {

using namespace sync_test;  // NOLINT(google-build-using-namespace): the shared test loop
using Report = SampleReport<double, 1, 1>;
constexpr double kNaNMeasurement = std::numeric_limits<double>::quiet_NaN();

/// A controller on the generated reference plant, its interface, and a report sender.
struct Loop {
  Disc disc{K::kTable};
  host::HostNetworkState net;
  Ctrl ctrl;
  Loop() : ctrl(make()) { net.address = kController; }
  Ctrl make() {
    Est est(K::kDesign, disc, NoiseModel::kExact);
    est.reset(Vector<double, 2>{}, K::kDesign.p0, Vector<double, 1>{});
    Vector<double, 2> nx;
    nx[0] = 1;
    Vector<double, 1> lo, hi, nu;
    lo[0] = -5;
    hi[0] = 5;
    return Ctrl(kActuator, K::kDesign.l, lo, hi, est, Ref(0.5, 50, nx, nu));
  }
  /// The sensor's report of period k with sample y (τ = 20 ms, echo u), handled at once.
  void report(SequenceNumber k, double y, double u = 0.0, std::uint8_t from = kSensor) {
    deliver_report(net, from, k, McuInstant(k * 50'000U), 20'000, y, u);
    const host::ScopedHostNetwork cur(net);
    ctrl.on_receive(McuInstant(k * 50'000U + 25'000U));
  }
  /// Commands sent so far.
  std::size_t commands() const { return net.outbox.size(); }
  /// Sequence number of the last command sent.
  SequenceNumber last_command_k() const {
    Message<VectorPayload<double, 1>> c;
    const auto& b = net.outbox.back().bytes;
    EXPECT_EQ(decode(b.data(), b.size(), c), FrameStatus::kOk);
    return c.seq;
  }
  bool estimate_finite() const {
    const auto x = const_cast<Ctrl&>(ctrl).estimator().estimate();
    return all_finite(x) && all_finite(ctrl.last_command());
  }
};

double genuine_y(SequenceNumber k) { return 0.2 * static_cast<double>(k % 7) - 0.6; }

TEST(SyncControllerValidation, NanSamplesNeverReachTheEstimate) {
  // GIVEN a running loop WHEN sixty reports carry NaN samples (the live attack)
  Loop l;
  for (SequenceNumber k = 1; k <= 20; ++k) l.report(k, genuine_y(k));
  ASSERT_EQ(l.commands(), 20U);
  for (SequenceNumber k = 21; k <= 80; ++k) l.report(k, kNaNMeasurement);
  // THEN the estimate and the command stay finite, and the loop goes on commanding
  EXPECT_TRUE(l.estimate_finite());
  for (SequenceNumber k = 81; k <= 100; ++k) l.report(k, genuine_y(k));
  EXPECT_TRUE(l.estimate_finite());
  EXPECT_EQ(l.commands(), 40U);
  EXPECT_EQ(l.last_command_k(), 100U);
  EXPECT_EQ(l.ctrl.statistics().refused_non_finite, 60U);
  // A NaN echo is refused the same way.
  l.report(101, genuine_y(101), kNaNMeasurement);
  EXPECT_TRUE(l.estimate_finite());
  EXPECT_EQ(l.ctrl.statistics().refused_non_finite, 61U);
}

TEST(SyncControllerValidation, OneForgedFutureSequenceDoesNotStopTheLoop) {
  // GIVEN a running loop WHEN one report arrives 2^31 − 2^16 periods ahead
  Loop l;
  for (SequenceNumber k = 1; k <= 20; ++k) l.report(k, genuine_y(k));
  l.report(20U + (1U << 31) - (1U << 16), genuine_y(0));
  // THEN every later genuine report is still used: one command each, for its period
  for (SequenceNumber k = 21; k <= 60; ++k) {
    l.report(k, genuine_y(k));
    ASSERT_EQ(l.last_command_k(), k);
  }
  EXPECT_EQ(l.commands(), 60U);
  EXPECT_TRUE(l.estimate_finite());
  EXPECT_EQ(l.ctrl.statistics().refused_sequence, 1U);
}

TEST(SyncControllerValidation, RestartedActuatorIsReacquiredWithinRReports) {
  // GIVEN 200 periods WHEN the actuator restarts (k from 1 again)
  Loop l;
  for (SequenceNumber k = 1; k <= 200; ++k) l.report(k, genuine_y(k));
  const std::size_t before = l.commands();
  SequenceNumber k = 1;
  for (; l.commands() == before && k <= 10; ++k) l.report(k, genuine_y(k));
  // THEN commands resume on the R-th report of the new epoch, for that period
  EXPECT_EQ(k - 1, kDefaultReacquireFrames);
  EXPECT_EQ(l.last_command_k(), kDefaultReacquireFrames);
  for (; k <= 20; ++k) {
    l.report(k, genuine_y(k));
    EXPECT_EQ(l.last_command_k(), k);
  }
  EXPECT_EQ(l.ctrl.statistics().reacquired, 1U);
}

TEST(SyncControllerValidation, SourceRangeAndTauAreChecked) {
  Loop l;
  l.ctrl.expect_source(kSensor);
  Vector<double, 1> lo, hi;
  lo[0] = -2;
  hi[0] = 2;
  l.ctrl.set_measurement_range(lo, hi);
  l.ctrl.check_echo_range();
  l.ctrl.set_tau_range(0, 50'000);
  l.report(1, genuine_y(1));
  l.report(2, genuine_y(2), 0.0, kActuator);  // not the sensor
  l.report(3, 2.5);                           // y outside the ADC range
  l.report(4, 0.1, 6.0);                      // echo outside [u_min, u_max]
  EXPECT_EQ(l.commands(), 1U);
  const auto& s = l.ctrl.statistics();
  EXPECT_EQ(s.refused_source, 1U);
  EXPECT_EQ(s.refused_out_of_range, 2U);
  Report r;
  r.k = 5;
  r.tau_us = 60'000;  // beyond τ_max
  std::uint8_t bytes[kMaxMessageBytes];
  const std::size_t n = encode(r, bytes);
  l.net.deliver(host::Frame{kSensor, kController, std::vector<std::uint8_t>(bytes, bytes + n)});
  {
    const host::ScopedHostNetwork cur(l.net);
    l.ctrl.on_receive(McuInstant(0));
  }
  EXPECT_EQ(s.refused_out_of_range, 3U);
  l.report(6, genuine_y(6));
  EXPECT_EQ(l.commands(), 2U);
}

TEST(SyncEstimatorValidation, NonFiniteResultResetsToTheDesign) {
  // GIVEN the half Kalman estimator WHEN fed samples so large that x̂ overflows
  const Disc disc(K::kTable);
  Est est(K::kDesign, disc, NoiseModel::kExact);
  Vector<double, 2> x0;
  x0[0] = 0.25;
  est.reset(x0, K::kDesign.p0, Vector<double, 1>{});
  Vector<double, 1> y, u;
  y[0] = std::numeric_limits<double>::max();
  u[0] = std::numeric_limits<double>::max();
  Status s = Status::kOk;
  for (int i = 0; i < 50 && s != Status::kNonFinite; ++i) {
    s = est.update(20'000, y, u);
    ASSERT_TRUE(all_finite(est.estimate())) << i;
  }
  // THEN it reports kNonFinite and holds the design's initial estimate and covariance
  ASSERT_EQ(s, Status::kNonFinite);
  EXPECT_EQ(est.estimate()[0], 0.25);
  EXPECT_EQ(est.estimate()[1], 0.0);
  for (std::size_t i = 0; i < 4; ++i) EXPECT_EQ(est.filter().covariance()[i], K::kDesign.p0[i]);
  // and a sane sample afterwards is used normally
  y[0] = 0.1;
  u[0] = 0.0;
  EXPECT_TRUE(is_exact(est.update(20'000, y, u)));
}

TEST(SyncSensorValidation, ForgedAndRestartedRequests) {
  host::HostNetworkState net;
  net.address = kSensor;
  SyncSensorNode<host::HostNetwork, double, 1, 1> sensor(kController, 0);
  sensor.expect_source(kActuator);
  sensor.set_stamp_window(150'000);
  const auto request = [&](SequenceNumber k, std::uint32_t t_k, double u, std::uint8_t from = kActuator) {
    ActuationRequest<double, 1> r;
    r.k = k;
    r.t_k = McuInstant(t_k);
    r.u_applied[0] = u;
    std::uint8_t bytes[kMaxMessageBytes];
    const std::size_t n = encode(r, bytes);
    net.deliver(host::Frame{from, kSensor, std::vector<std::uint8_t>(bytes, bytes + n)});
    const host::ScopedHostNetwork cur(net);
    McuInstant at;
    return sensor.on_receive(McuInstant(t_k - 50'000U), at);
  };
  for (SequenceNumber k = 1; k <= 30; ++k) ASSERT_TRUE(request(k, k * 50'000U, 0.1));
  EXPECT_FALSE(request(31U + (1U << 31) - (1U << 16), 31 * 50'000U, 0.1));  // forged k
  EXPECT_FALSE(request(31, 31 * 50'000U, kNaNMeasurement));                          // NaN echo
  EXPECT_FALSE(request(31, 31 * 50'000U, 0.1, kController));              // not the actuator
  EXPECT_TRUE(request(31, 31 * 50'000U, 0.1));                            // genuine
  // t_k 35 min ahead of the sensor's clock: refused (it would stall late sampling).
  ActuationRequest<double, 1> far;
  far.k = 32;
  far.t_k = McuInstant(32 * 50'000U + 2'000'000'000U);
  std::uint8_t bytes[kMaxMessageBytes];
  const std::size_t n = encode(far, bytes);
  net.deliver(host::Frame{kActuator, kSensor, std::vector<std::uint8_t>(bytes, bytes + n)});
  {
    const host::ScopedHostNetwork cur(net);
    McuInstant at;
    EXPECT_FALSE(sensor.on_receive(McuInstant(31 * 50'000U), at));
  }
  EXPECT_TRUE(request(32, 32 * 50'000U, 0.1));
  // The actuator restarts: k from 1 again, re-acquired on the R-th request.
  EXPECT_FALSE(request(1, 33 * 50'000U, 0.0));
  EXPECT_FALSE(request(2, 34 * 50'000U, 0.0));
  EXPECT_TRUE(request(3, 35 * 50'000U, 0.0));
  const auto& s = sensor.statistics();
  EXPECT_EQ(s.refused_sequence, 2U);
  EXPECT_EQ(s.refused_non_finite, 1U);
  EXPECT_EQ(s.refused_source, 1U);
  EXPECT_EQ(s.reacquired, 1U);
}

}  // namespace
}  // namespace oneshot::node
