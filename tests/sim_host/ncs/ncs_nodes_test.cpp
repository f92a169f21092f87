/// @file ncs_nodes_test.cpp
/// @brief The node roles of the actuation-synchronized loop (firmware/node/): messages,
///        the controller's estimate against the core's half Kalman filter (bit for bit),
///        its gain against the design step's periodic gain, the offset law Φ(τ)Kδ, late
///        sampling, and the late-command policy (hold, count, echo).
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>

#include "ncs_loop.hpp"
#include "ncs_reference.hpp"
#include "ncs_test_support.hpp"
#include "oneshot/engine/psd_math.hpp"
#include "oneshot/host/host_network.hpp"
#include "oneshot/node/sync_actuator_node.hpp"
#include "oneshot/node/sync_controller_node.hpp"
#include "oneshot/node/sync_estimators.hpp"
#include "oneshot/node/sync_sensor_node.hpp"
#include "oneshot/plant_structure.hpp"

namespace oneshot::ncs {
namespace {

using Board = host::HostNetwork;
using Structure = DenseStructure<kN, kM, kP>;
using Ref = node::SquareWaveReference<double, kN, kM>;
using HalfEst = node::HalfKalmanEstimator<Fmt, Structure, Disc>;
using Ctrl = node::SyncControllerNode<Board, HalfEst, Ref, double, kN, kP, kM>;
using Report = node::SampleReport<double, kP, kM>;
using Request = node::ActuationRequest<double, kM>;
using Command = node::Message<node::VectorPayload<double, kM>>;

Ref reference() {
  Vector<double, kN> nx;
  nx[0] = 1;
  return Ref(0.5, 20, nx, Vector<double, kM>{});
}

/// The input vector with every entry `v`.
Vector<double, kM> input_of(double v) {
  Vector<double, kM> u;
  for (std::size_t j = 0; j < kM; ++j) u[j] = v;
  return u;
}

/// The controller node (address 2, commanding the actuator at 3) with the design's gain,
/// commands clamped to ±u_max and the reference() square wave.
Ctrl controller(const Design& design, const HalfEst& est, double u_max) {
  return Ctrl(3, design.l, input_of(-u_max), input_of(u_max), est, reference());
}

template <typename M>
host::Frame frame(std::uint8_t src, std::uint8_t dst, const M& m) {
  std::uint8_t b[node::kMaxMessageBytes];
  const std::size_t n = node::encode(m, b);
  return host::Frame{src, dst, std::vector<std::uint8_t>(b, b + n)};
}

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

TEST(NcsMessages, RequestAndReportRoundTrip) {
  Report r;
  r.k = 0xFFFFFFF0U;
  r.t_s = McuInstant(123456789U);
  r.tau_us = -17;
  r.y[0] = 0.25;
  r.y[1] = -1e-300;
  r.u_applied[0] = -1.5;
  std::uint8_t b[node::kMaxMessageBytes];
  const std::size_t n = node::encode(r, b);
  Report d;
  ASSERT_EQ(node::decode(b, n, d), node::FrameStatus::kOk);
  EXPECT_EQ(d.k, r.k);
  EXPECT_EQ(d.t_s, r.t_s);
  EXPECT_EQ(d.tau_us, -17);
  EXPECT_TRUE(same_bits(d.y[1], r.y[1]));
  EXPECT_EQ(d.u_applied[0], -1.5);
  Request q;
  EXPECT_EQ(node::decode(b, n, q), node::FrameStatus::kMalformed);  // a report is not a request
  EXPECT_EQ(node::decode(b, n - 1, d), node::FrameStatus::kMalformed);
}

/// The controller node's estimate is the core's half Kalman filter, bit for bit, on random
/// τ, samples and echoed inputs; its command is u_ref − L(x̂ − x_ref) clamped.
TEST(NcsNodes, ControllerEstimateIsTheCoreHalfKalmanBitForBit) {
  const Context& ctx = context();
  for (NoiseModel noise : {NoiseModel::kConstant, NoiseModel::kExact}) {
    const Design design = ctx.controller_design(4.0);
    const Disc disc(ctx.discretizer_model(4.0));
    Vector<double, kN> x0;
    x0[0] = 0.5;
    HalfEst est(design, disc, noise);
    est.reset(x0, design.p0, Vector<double, kM>{});
    HalfKalman<Fmt, Structure, Disc> core(design, disc, noise);
    core.reset(x0, design.p0, Vector<double, kM>{});
    Ctrl ctrl = controller(design, est, 1.65);
    host::HostNetworkState net;
    net.address = 2;
    const host::ScopedHostNetwork scope(net);
    std::mt19937_64 rng(7);
    std::uniform_int_distribution<std::int32_t> tau(1000, 49'500);
    std::normal_distribution<double> y(0, 0.3);
    for (node::SequenceNumber k = 1; k <= 300; ++k) {
      Report r;
      r.k = k;
      r.tau_us = tau(rng);
      r.y[0] = y(rng);
      r.y[1] = y(rng);
      r.u_applied[0] = y(rng);
      net.deliver(frame(1, 2, r));
      ctrl.on_receive(McuInstant(k * 50'000U));
      core.set_applied_input(r.u_applied);
      ASSERT_EQ(core.update(r.tau_us, r.y), Status::kOk);
      for (std::size_t i = 0; i < kN; ++i) ASSERT_TRUE(same_bits(ctrl.estimator().estimate()[i], core.prediction()[i])) << k;
      ASSERT_EQ(net.outbox.size(), 1U);
      Command c;
      ASSERT_EQ(node::decode(net.outbox[0].bytes.data(), net.outbox[0].bytes.size(), c), node::FrameStatus::kOk);
      net.outbox.clear();
      EXPECT_EQ(c.seq, k);
      Vector<double, kM> u = reference().input(k) - design.l * (core.prediction() - reference().state(k));
      node::saturate(u, input_of(-1.65), input_of(1.65));
      EXPECT_TRUE(same_bits(c.payload.value[0], u[0]));
    }
    EXPECT_EQ(ctrl.statistics().computations, 300U);
    // A repeated report is dropped and counted, never re-filtered.
    Report again;
    again.k = 300;
    net.deliver(frame(1, 2, again));
    ctrl.on_receive(McuInstant(0));
    EXPECT_EQ(ctrl.statistics().stale, 1U);
    EXPECT_TRUE(net.outbox.empty());
  }
}

/// With exact Q_d and a constant τ_as, the sample-to-sample covariance recursion is the
/// periodic filter's at h, so K converges to the design step's steady gain whatever τ_as.
TEST(NcsNodes, GainWithExactQdAndConstantTauEqualsThePeriodicGain) {
  const Context& ctx = context();
  const Design design = ctx.controller_design(1.0);
  const Disc disc(ctx.discretizer_model(1.0));
  const design::DenseMatrix& k_ref = ctx.design().kalman_gain;  // `design --json`: kalman_gain
  for (std::int32_t tau_as : {500, 7'300, 14'000, 30'000}) {
    HalfEst est(design, disc, NoiseModel::kExact);
    est.reset(Vector<double, kN>{}, design.p0, Vector<double, kM>{});
    for (int k = 0; k < 400; ++k) {
      ASSERT_TRUE(is_exact(est.update(design.period_us - tau_as, Vector<double, kP>{}, Vector<double, kM>{})));
    }
    double err = 0;
    for (std::size_t i = 0; i < kN; ++i)
      for (std::size_t j = 0; j < kP; ++j) err = std::fmax(err, std::fabs(est.filter().gain()(i, j) - k_ref(i, j)));
    EXPECT_LT(err, 1e-14) << "tau_as " << tau_as;  // issue: 1e-9; measured 1.0e-15
  }
  // With the constant Q of the paper the gain depends on τ_as: the check is not vacuous.
  HalfEst est(design, disc, NoiseModel::kConstant);
  est.reset(Vector<double, kN>{}, design.p0, Vector<double, kM>{});
  for (int k = 0; k < 400; ++k) {
    ASSERT_TRUE(is_exact(est.update(design.period_us - 14'000, Vector<double, kP>{}, Vector<double, kM>{})));
  }
  EXPECT_GT(std::fabs(est.filter().gain()(0, 0) - k_ref(0, 0)), 1e-4);
}

/// An offset δ on the sample of period k moves x̂⁻_k by Φ(τ_k) K_k δ.
TEST(NcsNodes, MeasurementOffsetMovesThePredictionByPhiKDelta) {
  const Context& ctx = context();
  const Design design = ctx.controller_design(1.0);
  const Disc disc(ctx.discretizer_model(1.0));
  std::mt19937_64 rng(3);
  std::uniform_int_distribution<std::int32_t> tau(1000, 49'000);
  std::normal_distribution<double> y(0, 0.2);
  double worst = 0;
  for (int trial = 0; trial < 50; ++trial) {
    HalfEst a(design, disc, NoiseModel::kExact);
    a.reset(Vector<double, kN>{}, design.p0, Vector<double, kM>{});
    for (int k = 0; k < 10; ++k) {
      Vector<double, kP> yk;
      yk[0] = y(rng);
      yk[1] = y(rng);
      Vector<double, kM> u;
      u[0] = y(rng);
      ASSERT_TRUE(is_exact(a.update(tau(rng), yk, u)));
    }
    HalfEst b = a;
    Vector<double, kP> yk;
    yk[0] = y(rng);
    yk[1] = y(rng);
    Vector<double, kP> delta;
    delta[0] = 0.01 * y(rng);
    delta[1] = 0.01 * y(rng);
    Vector<double, kM> u;
    u[0] = y(rng);
    const std::int32_t t = tau(rng);
    ASSERT_TRUE(is_exact(a.update(t, yk, u)));
    ASSERT_TRUE(is_exact(b.update(t, yk + delta, u)));
    Disc::Triple d;
    ASSERT_EQ(disc.discretize(t, d, WithQd::kNo), Status::kOk);
    const Vector<double, kN> expect = d.phi * (a.filter().gain() * delta);
    for (std::size_t i = 0; i < kN; ++i) worst = std::fmax(worst, std::fabs((b.estimate()[i] - a.estimate()[i]) - expect[i]));
  }
  EXPECT_LT(worst, 4e-15);  // rounding of x̂ ~ 0.2 only (measured 1.1e-15; Φ K δ itself ~ 1e-3)
}

TEST(NcsNodes, SensorSamplesAtOnceOrLateAtTkMinusD) {
  host::HostNetworkState net;
  net.address = 1;
  const host::ScopedHostNetwork scope(net);
  node::SyncSensorNode<Board, double, kP, kM> at_once(2, 0);
  node::SyncSensorNode<Board, double, kP, kM> late(2, 33'000);
  Request q;
  q.k = 5;
  q.t_k = McuInstant(250'000);
  q.u_applied[0] = 0.7;
  McuInstant when;
  net.deliver(frame(3, 1, q));
  ASSERT_TRUE(at_once.on_receive(McuInstant(204'000), when));
  EXPECT_EQ(when, McuInstant(204'000));
  net.deliver(frame(3, 1, q));
  ASSERT_TRUE(late.on_receive(McuInstant(204'000), when));
  EXPECT_EQ(when, McuInstant(217'000));  // t_k − D
  Vector<double, kP> y;
  y[0] = 0.1;
  ASSERT_EQ(late.on_sample(when, y), node::ReportResult::kSent);
  Report r;
  ASSERT_EQ(node::decode(net.outbox.back().bytes.data(), net.outbox.back().bytes.size(), r), node::FrameStatus::kOk);
  EXPECT_EQ(r.k, 5U);
  EXPECT_EQ(r.tau_us, 33'000);
  EXPECT_EQ(r.u_applied[0], 0.7);
  // A request arriving after t_k − D is sampled at once.
  q.k = 6;
  q.t_k = McuInstant(300'000);
  net.deliver(frame(3, 1, q));
  ASSERT_TRUE(late.on_receive(McuInstant(280'000), when));
  EXPECT_EQ(when, McuInstant(280'000));
}

/// A late command: the actuator holds the previous value, counts the miss, echoes the value
/// it really applied, and the controller predicts with that echo.
TEST(NcsNodes, LateCommandIsHeldCountedAndItsEchoUsed) {
  host::HostNetworkState act_net;
  act_net.address = 3;
  node::SyncActuatorNode<Board, double, kM> act(1, Vector<double, kM>{});
  const auto command = [&](node::SequenceNumber k, double u) {
    Command c;
    c.seq = k;
    c.payload.value[0] = u;
    act_net.deliver(frame(2, 3, c));
  };
  const auto last_request = [&]() {
    Request q;
    EXPECT_EQ(node::decode(act_net.outbox.back().bytes.data(), act_net.outbox.back().bytes.size(), q), node::FrameStatus::kOk);
    return q;
  };
  Vector<double, kM> out;
  {
    const host::ScopedHostNetwork scope(act_net);
    act.start(McuInstant(50'000));
    EXPECT_EQ(last_request().k, 1U);
    command(1, 0.4);
    act.on_receive();
    act.on_timer(1, McuInstant(100'000));  // in time
    ASSERT_TRUE(act.take_output(out));
    EXPECT_EQ(out[0], 0.4);
    EXPECT_EQ(last_request().u_applied[0], 0.4);
    act.on_timer(2, McuInstant(150'000));  // command 2 never came: hold 0.4
    EXPECT_FALSE(act.take_output(out));
    EXPECT_EQ(act.statistics().late, 1U);
    command(2, -0.9);  // arrives after t_2: never applied
    act.on_receive();
    EXPECT_EQ(last_request().k, 3U);
    EXPECT_EQ(last_request().u_applied[0], 0.4);  // the echo is what the plant got
  }
  const Request q3 = last_request();
  EXPECT_EQ(act.statistics().late, 1U);
  EXPECT_EQ(act.applied()[0], 0.4);
  // The controller predicts over t_2 → t_3 with the echoed 0.4, not its own −0.9.
  const Context& ctx = context();
  const Design design = ctx.controller_design(1.0);
  const Disc disc(ctx.discretizer_model(1.0));
  HalfEst est(design, disc, NoiseModel::kConstant);
  est.reset(Vector<double, kN>{}, design.p0, Vector<double, kM>{});
  HalfKalman<Fmt, Structure, Disc> with_echo(design, disc, NoiseModel::kConstant);
  with_echo.reset(Vector<double, kN>{}, design.p0, Vector<double, kM>{});
  HalfKalman<Fmt, Structure, Disc> with_own(design, disc, NoiseModel::kConstant);
  with_own.reset(Vector<double, kN>{}, design.p0, Vector<double, kM>{});
  Ctrl ctrl = controller(design, est, 2);
  host::HostNetworkState ctrl_net;
  ctrl_net.address = 2;
  const host::ScopedHostNetwork scope(ctrl_net);
  Report r;
  r.k = q3.k;
  r.tau_us = 40'000;
  r.y[0] = 0.05;
  r.u_applied = q3.u_applied;
  ctrl_net.deliver(frame(1, 2, r));
  ctrl.on_receive(McuInstant(120'000));
  with_echo.set_applied_input(q3.u_applied);
  ASSERT_TRUE(is_exact(with_echo.update(r.tau_us, r.y)));
  Vector<double, kM> own;
  own[0] = -0.9;
  with_own.set_applied_input(own);
  ASSERT_TRUE(is_exact(with_own.update(r.tau_us, r.y)));
  EXPECT_EQ(ctrl.estimator().estimate()[1], with_echo.prediction()[1]);
  EXPECT_NE(ctrl.estimator().estimate()[1], with_own.prediction()[1]);
}

TEST(NcsReference, TheSquareWaveFollowsItsLawAndSwitchesWhereTheSignFlips) {
  // The law written out here (r_k = +A in even half waves, −A in odd ones; x_ref = N_x r_k,
  // u_ref = N_u r_k), not taken from the firmware object SetpointReference delegates to.
  Vector<double, kN> nx;
  nx[0] = 1.3;
  nx[1] = -0.7;
  Vector<double, kM> nu;
  nu[0] = 0.45;
  const double amplitude = 0.37;
  for (const std::uint32_t half : {1U, 7U, 20U}) {
    const SetpointReference mine(amplitude, half, nx, nu);
    for (node::SequenceNumber k = 0; k < 200; ++k) {
      const double r = (k / half) % 2 == 0 ? amplitude : -amplitude;
      const double b = mine.setpoint(k);
      ASSERT_EQ(std::memcmp(&r, &b, sizeof r), 0) << half << " " << k;
      for (std::size_t i = 0; i < kN; ++i) ASSERT_EQ(nx[i] * r, mine.state(k)[i]) << k;
      for (std::size_t j = 0; j < kM; ++j) ASSERT_EQ(nu[j] * r, mine.input(k)[j]) << k;
    }
    const std::vector<std::uint64_t> sw = mine.switches(60);  // every half wave, where the sign flips
    for (std::size_t i = 0; i < sw.size(); ++i) EXPECT_EQ(sw[i], (i + 1) * half);
    EXPECT_EQ(sw.size(), (60 - 1) / half);
  }
}

TEST(NcsShapes, TheMeasurementFactorOfAnyOutputCountMultipliesBackToItsCovariance) {
  // The oracle: L Lᵀ = R to rounding for a regular R of 1, 2, 3 and 4 outputs (L lower, its
  // diagonal positive), and a column of 0 for a singular R (noise scale 0).
  std::mt19937_64 gen(26);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const auto check = [&](auto r, double tol) {
    constexpr std::size_t kDim = decltype(r)::kRows;
    const auto l = engine::psd_cholesky<kDim>(r);
    for (std::size_t i = 0; i < kDim; ++i) {
      EXPECT_GT(l(i, i), 0.0);
      for (std::size_t j = 0; j < kDim; ++j) {
        if (j > i) {
          EXPECT_EQ(l(i, j), 0.0);
        }
        double s = 0;
        for (std::size_t k = 0; k < kDim; ++k) s += l(i, k) * l(j, k);
        EXPECT_NEAR(s, r(i, j), tol) << kDim << " " << i << " " << j;
      }
    }
  };
  const auto random_spd = [&](auto zero) {  // G Gᵀ + I: symmetric positive definite
    decltype(zero) g{}, r{};
    constexpr std::size_t kDim = decltype(zero)::kRows;
    for (std::size_t i = 0; i < kDim; ++i)
      for (std::size_t j = 0; j < kDim; ++j) g(i, j) = u(gen);
    for (std::size_t i = 0; i < kDim; ++i)
      for (std::size_t j = 0; j < kDim; ++j) {
        r(i, j) = i == j ? 1.0 : 0.0;
        for (std::size_t k = 0; k < kDim; ++k) r(i, j) += g(i, k) * g(j, k);
      }
    return r;
  };
  for (int trial = 0; trial < 20; ++trial) {
    check(random_spd(Matrix<double, 1, 1>{}), 1e-14);
    check(random_spd(Matrix<double, 2, 2>{}), 1e-13);
    check(random_spd(Matrix<double, 3, 3>{}), 1e-13);
    check(random_spd(Matrix<double, 4, 4>{}), 1e-13);
  }
  const Matrix<double, 2, 2> zero{};
  const auto l0 = engine::psd_cholesky<2>(zero);
  for (std::size_t i = 0; i < 2; ++i)
    for (std::size_t j = 0; j < 2; ++j) EXPECT_EQ(l0(i, j), 0.0);
}

}  // namespace
}  // namespace oneshot::ncs
