/// @file sync_controller_gap_test.cpp
/// @brief The synchronized controller over periods without a report (issue 24): with the
///        period set, a missing report is predicted over with the next report's echo
///        (oracle: the estimator fed the same reports with skip() in the gap, bit for bit);
///        a restarted actuator (k from 1 again, stamps going on) gives the same commands as
///        the same reports with k going on and the two refused ones lost (the reference
///        follows the stamps, not k); without the period nothing changes.
#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

#include "oneshot/host/host_network.hpp"
#include "oneshot/node/sync_controller_node.hpp"
#include "oneshot/node/sync_estimators.hpp"
#include "oneshot/table_discretizer.hpp"
#include "sync_test_loop.hpp"

namespace oneshot::node {
namespace {

using namespace sync_test;  // NOLINT(google-build-using-namespace): the shared test loop
constexpr std::uint32_t kH = 50'000;  // the generated plant's period (µs)
constexpr std::int32_t kTau = 20'000;

Est estimator(const Disc& disc) {
  Est est(K::kDesign, disc, NoiseModel::kExact);
  est.reset(Vector<double, 2>{}, K::kDesign.p0, Vector<double, 1>{});
  return est;
}

/// A controller whose reports carry k and the actuation instant of period n (t_s = n·h − τ).
struct GapLoop {
  Disc disc{K::kTable};
  host::HostNetworkState net;
  Ctrl ctrl;
  explicit GapLoop(bool with_period) : ctrl(make()) {
    net.address = kController;
    if (with_period) ctrl.set_period_us(static_cast<std::int32_t>(kH));
  }
  Ctrl make() {
    Vector<double, 2> nx;
    nx[0] = 1;
    Vector<double, 1> lo, hi, nu;
    lo[0] = -5;
    hi[0] = 5;
    return Ctrl(kActuator, K::kDesign.l, lo, hi, estimator(disc), Ref(0.5, 8, nx, nu));
  }
  void report(SequenceNumber k, std::uint32_t n, double y, double u) {
    deliver_report(net, kSensor, k, McuInstant(n * kH - static_cast<std::uint32_t>(kTau)), kTau, y, u);
    const host::ScopedHostNetwork cur(net);
    ctrl.on_receive(McuInstant(n * kH - 5'000U));
  }
  /// Value of the last command sent.
  double last_u() const {
    Message<VectorPayload<double, 1>> c;
    const auto& b = net.outbox.back().bytes;
    EXPECT_EQ(decode(b.data(), b.size(), c), FrameStatus::kOk);
    return c.payload.value[0];
  }
};

double y_of(std::uint32_t n) { return 0.05 * static_cast<double>(n % 9) - 0.2; }
double u_of(std::uint32_t n) { return 0.01 * static_cast<double>(n % 5); }

TEST(SyncControllerGap, MissingReportIsPredictedOverWithTheEcho) {
  // GIVEN reports of periods 1–20 with period 8 lost
  GapLoop l(true);
  const Disc disc(K::kTable);
  Est oracle = estimator(disc);
  for (std::uint32_t n = 1; n <= 20; ++n) {
    if (n == 8) continue;
    l.report(n, n, y_of(n), u_of(n));
    Vector<double, 1> y, u;
    y[0] = y_of(n);
    u[0] = u_of(n);
    if (n == 9) {
      ASSERT_EQ(oracle.skip(u), Status::kOk);  // the gap: predicted over with report 9's echo
    }
    static_cast<void>(oracle.update(kTau, y, u));
    // THEN the controller's estimate is the oracle's, bit for bit
    ASSERT_EQ(l.ctrl.estimator().estimate()[0], oracle.estimate()[0]) << n;
    ASSERT_EQ(l.ctrl.estimator().estimate()[1], oracle.estimate()[1]) << n;
  }
  EXPECT_EQ(l.ctrl.statistics().filled, 1U);
}

TEST(SyncControllerGap, WithoutThePeriodNothingIsFilled) {
  GapLoop l(false);
  for (std::uint32_t n = 1; n <= 20; ++n)
    if (n != 8) l.report(n, n, y_of(n), u_of(n));
  EXPECT_EQ(l.ctrl.statistics().filled, 0U);
}

TEST(SyncControllerGap, RestartedActuatorIsTwoLostReportsNotAReferenceJump) {
  // GIVEN 40 periods, then the actuator restarts: its k runs from 1 again while the
  // actuation instants go on (periods 41, 42, … carry k = 1, 2, …)
  GapLoop restarted(true), lost(true);
  std::vector<double> a, b;
  for (std::uint32_t n = 1; n <= 40; ++n) {
    restarted.report(n, n, y_of(n), u_of(n));
    lost.report(n, n, y_of(n), u_of(n));
  }
  for (std::uint32_t n = 41; n <= 70; ++n) {
    const std::size_t before = restarted.net.outbox.size();
    restarted.report(n - 40, n, y_of(n), u_of(n));
    if (restarted.net.outbox.size() > before) a.push_back(restarted.last_u());
    if (n <= 42) continue;  // the two reports of the new epoch the controller refuses, lost
    lost.report(n, n, y_of(n), u_of(n));
    b.push_back(lost.last_u());
  }
  // THEN the restarted loop's commands are those of a loop that lost two reports
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) EXPECT_EQ(a[i], b[i]) << i;
  EXPECT_EQ(restarted.ctrl.statistics().reacquired, 1U);
  EXPECT_EQ(restarted.ctrl.statistics().filled, 2U);
}

}  // namespace
}  // namespace oneshot::node
