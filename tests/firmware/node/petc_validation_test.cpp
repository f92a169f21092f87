/// @file petc_validation_test.cpp
/// @brief The PETC controller node refuses NaN and out-of-window arrivals (issue 24): the
///        NUMRE estimate stays finite, a forged far-future period neither stalls the node
///        (no 2^31-period prediction) nor stops later arrivals, a restarted sensor is
///        re-acquired on its R-th arrival, and a non-finite correction resets the NUMRE.
#include <gtest/gtest.h>

#include <cstdint>
#include <limits>

#include "oneshot/node/disturbance_observer.hpp"
#include "oneshot/node/interlaced_controller.hpp"
#include "oneshot/node/petc_controller.hpp"
#include "support/numre_test_model.hpp"

namespace oneshot::node {
namespace {

using Law = InterlacedController<double, 1, 2>;
using Petc = PetcController<double, 2, 8, Law, ModelDisturbance<double>>;

Petc make() {
  InterlacedConfig<double, 1, 2> c{};
  c.feedthrough = 0.5;
  c.ratio = 2;
  return Petc(test::small_numre_model(), NoiseAccumulation::kSum, Law(c), ModelDisturbance<double>{},
              MtmTrigger<double, 1>(0.01, 1e-4, 4, 0), 0.3);
}

bool finite_state(const Petc& p) {
  for (std::size_t l = 0; l < Petc::kEntries; ++l)
    if (!is_finite(p.packet()[l])) return false;
  return all_finite(p.estimator().state()) && all_finite(p.estimator().covariance());
}

TEST(PetcValidation, NanArrivalsRefusedEstimateFinite) {
  Petc p = make();
  for (std::uint32_t k = 0; k < 20; ++k) static_cast<void>(p.on_arrival(k, 0.01 * k));
  const std::uint32_t sent_at = p.packet_start();
  for (std::uint32_t k = 20; k < 80; ++k) EXPECT_EQ(p.on_arrival(k, std::numeric_limits<double>::quiet_NaN()), SendCause::kNone);
  EXPECT_TRUE(finite_state(p));
  EXPECT_EQ(p.packet_start(), sent_at);
  // Genuine arrivals after the NaN burst are used (the MTM safety k_max = 4 sends).
  for (std::uint32_t k = 80; k < 90; ++k) static_cast<void>(p.on_arrival(k, 0.1));
  EXPECT_TRUE(finite_state(p));
  EXPECT_GE(p.packet_start(), 85U);
  EXPECT_EQ(p.statistics().refused_non_finite, 60U);
}

TEST(PetcValidation, ForgedFuturePeriodAndRestartedSensor) {
  Petc p = make();
  for (std::uint32_t k = 0; k < 20; ++k) static_cast<void>(p.on_arrival(k, 0.05));
  // One arrival 2^31 − 2^16 periods ahead: refused at once (no prediction over it).
  EXPECT_EQ(p.on_arrival(20U + (1U << 31) - (1U << 16), 0.05), SendCause::kNone);
  for (std::uint32_t k = 20; k < 30; ++k) static_cast<void>(p.on_arrival(k, 0.05));
  EXPECT_GE(p.packet_start(), 25U);
  EXPECT_EQ(p.estimator().last_multiplicity(), 1U);  // the last arrival predicted one period
  // The sensor restarts: periods from 0 again, re-acquired on the R-th arrival.
  const std::uint32_t before = p.packet_start();
  for (std::uint32_t k = 0; k + 1 < kDefaultReacquireFrames; ++k) EXPECT_EQ(p.on_arrival(k, 0.05), SendCause::kNone);
  static_cast<void>(p.on_arrival(kDefaultReacquireFrames - 1, 0.05));
  for (std::uint32_t k = kDefaultReacquireFrames; k < 12; ++k) static_cast<void>(p.on_arrival(k, 0.05));
  EXPECT_NE(p.packet_start(), before);
  EXPECT_LT(p.packet_start(), 12U);
  EXPECT_TRUE(finite_state(p));
  const auto& s = p.statistics();
  EXPECT_EQ(s.refused_sequence, 1U);
  EXPECT_EQ(s.reacquired, 1U);
  EXPECT_EQ(s.stale, kDefaultReacquireFrames - 1);
}

TEST(PetcValidation, NonFiniteCorrectionResetsTheNumre) {
  // GIVEN a NUMRE whose gain turns a huge (finite) measurement into an overflow
  NumreModel<double, 2> m = test::small_numre_model();
  m.c[0] = 1e-3;  // K ≈ 1/c = 1000: K (y − C x̂) overflows for y ≈ 1.7e308
  m.v = 1e-12;
  NumreEstimator<double, 2> est(m, NoiseAccumulation::kSum);
  Matrix<double, 2, 2> p0 = Matrix<double, 2, 2>::identity();
  Vector<double, 2> x0;
  x0[0] = 0.5;
  est.reset(x0, p0);
  EXPECT_EQ(est.correct(0.6), Status::kOk);
  est.predict(0.0);
  // WHEN y = 1.7e308 THEN the innovation overflows: reset to (x0, P0), kNonFinite
  EXPECT_EQ(est.correct(1.7e308), Status::kNonFinite);
  EXPECT_EQ(est.state()[0], 0.5);
  EXPECT_EQ(est.covariance()(1, 1), 1.0);
}

using Petc200 = PetcController<double, 2, 200, Law, ModelDisturbance<double>>;

/// The overflow fixture: the small NUMRE model with a_11 = 10 (×10 per period over H = 200 periods), reference r.
Petc200 unstable(double r) {
  NumreModel<double, 2> m = test::small_numre_model();
  m.a(1, 1) = 10.0;
  InterlacedConfig<double, 1, 2> c{};
  c.feedthrough = 0.5;
  c.ratio = 2;
  return Petc200(m, NoiseAccumulation::kSum, Law(c), ModelDisturbance<double>{}, MtmTrigger<double, 1>(0.01, 1e-4, 0, 0), r);
}

TEST(PetcValidation, OverflowingCascadeWithheldPacketInForceRegenerated) {
  // GIVEN an unstable model (a_11 = 10: ×10 per period over H = 200 periods) and a packet in
  // force sent with r = 0.3 (finite: about 1e198 at its end)
  Petc200 p = unstable(0.3);
  EXPECT_EQ(p.on_arrival(0, 0.05), SendCause::kFirst);
  static double before[Petc200::kEntries];
  static double d_before[Petc200::kEntries];
  for (std::size_t l = 0; l < Petc200::kEntries; ++l) {
    before[l] = p.packet()[l];
    d_before[l] = p.last_cascade_d_hat()[l];
    ASSERT_TRUE(is_finite(before[l]));
  }
  static Vector<double, 2> ref_before[Petc200::kEntries + 1];
  for (std::uint32_t j = 0; j <= Petc200::kEntries; ++j) ref_before[j] = p.reference_state(j);
  // WHEN r = 1e150: u_0 ≈ 5e149 is finite and sent by the delta rule, but the cascade
  // overflows part way through, after entries 0 … l were written into the packet in force
  p.set_reference(1e150);
  EXPECT_EQ(p.on_arrival(1, 0.05), SendCause::kNone);
  // THEN the cascade is withheld and the packet in force is the one before, bit for bit
  EXPECT_EQ(p.statistics().withheld, 1U);
  EXPECT_EQ(p.packet_start(), 0U);
  for (std::size_t l = 0; l < Petc200::kEntries; ++l) {
    EXPECT_EQ(p.packet()[l], before[l]) << l;
    EXPECT_EQ(p.last_cascade_d_hat()[l], d_before[l]) << l;
  }
  for (std::uint32_t j = 0; j <= Petc200::kEntries; ++j)
    for (std::size_t i = 0; i < 2; ++i) EXPECT_EQ(p.reference_state(j)[i], ref_before[j][i]) << j;
  EXPECT_TRUE(all_finite(p.estimator().state()));
  // AND with r back to 0.3, the next arrival predicts one period along the regenerated packet
  p.set_reference(0.3);
  static_cast<void>(p.on_arrival(2, 0.05));
  EXPECT_EQ(p.estimator().last_multiplicity(), 1U);
  EXPECT_TRUE(all_finite(p.estimator().state()));
}

TEST(PetcValidation, OverflowingFirstCascadeLeavesNoPacket) {
  // GIVEN the unstable model and r = 1e150 from the start (no packet in force yet)
  Petc200 p = unstable(1e150);
  // WHEN the first cascade overflows THEN nothing is sent, no packet is in force (all zero)
  EXPECT_EQ(p.on_arrival(0, 0.05), SendCause::kNone);
  EXPECT_EQ(p.statistics().withheld, 1U);
  for (std::size_t l = 0; l < Petc200::kEntries; ++l) EXPECT_EQ(p.packet()[l], 0.0) << l;
  EXPECT_EQ(p.applied(5), 0.0);
  // AND a finite reference later gives the first packet (kFirst)
  p.set_reference(0.3);
  EXPECT_EQ(p.on_arrival(1, 0.05), SendCause::kFirst);
}

TEST(PetcValidation, ReacquiredArrivalPredictsNothingAndRebasesThePacket) {
  // GIVEN no safety send (k_max = 0) and a constant measurement: the delta rule stays silent
  InterlacedConfig<double, 1, 2> c{};
  c.feedthrough = 0.5;
  c.ratio = 2;
  Petc p(test::small_numre_model(), NoiseAccumulation::kSum, Law(c), ModelDisturbance<double>{}, MtmTrigger<double, 1>(0.01, 1e-4, 0, 0), 0.3);
  for (std::uint32_t k = 1000; k < 1010; ++k) static_cast<void>(p.on_arrival(k, 0.05));
  EXPECT_EQ(p.estimator().last_multiplicity(), 1U);
  // WHEN the sensor restarts (periods from 0)
  for (std::uint32_t k = 0; k + 1 < kDefaultReacquireFrames; ++k) EXPECT_EQ(p.on_arrival(k, 0.05), SendCause::kNone);
  // THEN the re-acquiring arrival predicts nothing over the unknown interval and re-bases the
  // packet in force (kFirst), so later arrivals predict one period, not 2^32 − 1000
  EXPECT_EQ(p.on_arrival(kDefaultReacquireFrames - 1, 0.05), SendCause::kFirst);
  EXPECT_EQ(p.estimator().last_multiplicity(), 0U);
  EXPECT_EQ(p.packet_start(), kDefaultReacquireFrames - 1);
  static_cast<void>(p.on_arrival(kDefaultReacquireFrames, 0.05));
  EXPECT_EQ(p.estimator().last_multiplicity(), 1U);
  EXPECT_EQ(p.statistics().reacquired, 1U);
  EXPECT_TRUE(finite_state(p));
}

}  // namespace
}  // namespace oneshot::node
