/// @file interlaced_test.cpp
/// @brief MRCI (numre-petc.md §2): the decomposition against the printed slow modes, the
///        interlaced controller against the undivided one (m = 1: C_D's difference
///        equation; m = 2: each slow mode equals the undivided mode on the held error,
///        sampled on its schedule), and the actuator's packet buffer.
#include <gtest/gtest.h>

#include <string>

#include <cmath>
#include <random>
#include <vector>

#include "oneshot/node/interlaced_controller.hpp"
#include "oneshot/node/packet_buffer.hpp"
#include "petc_design.hpp"
#include "support/measured_text.hpp"

namespace {

using oneshot::test::sci;

using namespace oneshot::sim::petc;
using InterlacedLaw = oneshot::node::InterlacedController<double, 1, 2>;

InterlacedLaw make(const MrciDesign& d, bool at_update = false) {
  oneshot::node::InterlacedConfig<double, 1, 2> cfg;
  cfg.feedthrough = d.feedthrough;
  cfg.ratio = static_cast<std::uint32_t>(d.ratio);
  cfg.sample_at_update = at_update;
  std::size_t f = 0, s = 0;
  for (const MrciMode& m : d.modes) {
    if (m.slow)
      cfg.slow[s++] = {m.residue, m.pole};
    else
      cfg.fast[f++] = {m.residue, m.pole};
  }
  return InterlacedLaw(cfg);
}

std::vector<double> errors(std::size_t n) {
  std::mt19937_64 rng(3);
  std::normal_distribution<double> g(0.0, 1.0);
  std::vector<double> e(n);
  for (double& x : e) x = g(rng);
  return e;
}

TEST(Mrci, DecompositionMatchesPrintedModes) {
  const MrciDesign d = brief_mrci(2);
  EXPECT_EQ(d.slow_count, 2U);
  EXPECT_EQ(d.fast_count, 1U);
  EXPECT_DOUBLE_EQ(d.cs, 1.0 / 3.0);
  // Printed: 0.04484/(z² − 1), −1.6365/(z² − 0.7218), fast (1.0882 z + 1.84)/(z − 0.6137);
  // recomputed from the 4-digit poles and zeros they differ by up to ~0.4 % (brief: ≤ 0.5 %).
  EXPECT_NEAR(d.modes[0].slow_numerator / 0.04484, 1.0, 5e-3);
  EXPECT_NEAR(d.modes[1].slow_numerator / -1.6365, 1.0, 5e-3);
  EXPECT_NEAR(d.modes[1].slow_pole, 0.7218, 5e-5);
  EXPECT_DOUBLE_EQ(d.modes[0].slow_pole, 1.0);
  ASSERT_EQ(d.fast_numerator.size(), 2U);
  EXPECT_NEAR(d.fast_numerator[1] / 1.84, 1.0, 5e-3);
  EXPECT_DOUBLE_EQ(d.fast_numerator[0], 1.0882);
  EXPECT_DOUBLE_EQ(d.fast_denominator[1], -0.6137);
  // Residues rebuild C_D: at z = 2, D + Σ r/(z − p) equals the factored form.
  double sum = d.feedthrough;
  for (const MrciMode& m : d.modes) sum += m.residue / (2.0 - m.pole);
  const double direct = 1.0882 * (2 - 0.9813) * (2 - 0.9681) * 3 / ((2 - 1) * (2 - 0.8496) * (2 - 0.6137));
  EXPECT_NEAR(sum, direct, 1e-12 * direct);
  // m = 3: threshold e^{−1/7.5} = 0.875 leaves 0.8496 fast; CS = (1 − 1)/(1 + 2) = 0.
  const MrciDesign d3 = brief_mrci(3);
  EXPECT_EQ(d3.slow_count, 1U);
  EXPECT_DOUBLE_EQ(d3.cs, 0.0);
  // Its fast part D + r₂/(z − p₂) + r₃/(z − p₃) over (z − p₂)(z − p₃), checked at z = 2.
  ASSERT_EQ(d3.fast_numerator.size(), 3U);
  const auto& fn = d3.fast_numerator;
  const auto& fd = d3.fast_denominator;
  const double at2 = (fn[0] * 4 + fn[1] * 2 + fn[2]) / (fd[0] * 4 + fd[1] * 2 + fd[2]);
  EXPECT_NEAR(at2, d3.feedthrough + d3.modes[1].residue / (2 - 0.8496) + d3.modes[2].residue / (2 - 0.6137), 1e-12);
  EXPECT_THROW(brief_mrci(0), std::invalid_argument);
}

// m = 1: the controller is C_D, u_k = −a₁u_{k−1} − a₂u_{k−2} − a₃u_{k−3} + Σ b_i e_{k−i}.
TEST(Mrci, RatioOneEqualsUndividedDifferenceEquation) {
  MrciDesign d = design_mrci(1.0882, {0.9813, 0.9681, -1.0}, {1.0, 0.8496, 0.6137}, 1);
  // Force two slow modes at m = 1 (the split rule would call 0.8496 fast at m = 1).
  d.modes[1].slow = true;
  d.modes[2].slow = false;
  InterlacedLaw law = make(d);
  const double z1 = 0.9813, z2 = 0.9681, z3 = -1.0, p1 = 1.0, p2 = 0.8496, p3 = 0.6137, g = 1.0882;
  const double b[4] = {g, -g * (z1 + z2 + z3), g * (z1 * z2 + z1 * z3 + z2 * z3), -g * z1 * z2 * z3};
  const double a[4] = {1, -(p1 + p2 + p3), p1 * p2 + p1 * p3 + p2 * p3, -p1 * p2 * p3};
  const std::vector<double> e = errors(400);
  std::vector<double> ref(e.size(), 0.0);
  double worst = 0, scale = 0;
  for (std::size_t k = 0; k < e.size(); ++k) {
    double u = 0;
    for (std::size_t i = 0; i < 4 && i <= k; ++i) u += b[i] * e[k - i];
    for (std::size_t i = 1; i < 4 && i <= k; ++i) u -= a[i] * ref[k - i];
    ref[k] = u;
    const double got = law.step(k, e[k]);
    worst = std::max(worst, std::abs(got - u));
    scale = std::max(scale, std::abs(u));
  }
  RecordProperty("rel_err", sci(worst / scale));
  EXPECT_LT(worst / scale, 1e-12);  // measured 1.2e-13
}

// m = 2: u_k = D e_k + fast_k + Σ_i r_i x_i(m J), J = ⌊(k − φ_i)/m⌋, with x_i the undivided
// mode x⁺ = p_i x + ē driven by the held error ē_t = e_{m⌊t/m⌋}.
TEST(Mrci, InterlacedEqualsUndividedOnItsSchedule) {
  const MrciDesign d = brief_mrci(2);
  InterlacedLaw law = make(d);
  const std::size_t m = d.ratio;
  const std::vector<double> e = errors(400);
  std::vector<std::vector<double>> xund(d.modes.size(), std::vector<double>(e.size() + 1, 0.0));
  for (std::size_t i = 0; i < d.modes.size(); ++i)
    for (std::size_t t = 0; t < e.size(); ++t) {
      const double drive = d.modes[i].slow ? e[m * (t / m)] : e[t];
      xund[i][t + 1] = d.modes[i].pole * xund[i][t] + drive;
    }
  double worst = 0, scale = 0;
  for (std::size_t k = 0; k < e.size(); ++k) {
    double u = d.feedthrough * e[k];
    for (std::size_t i = 0; i < d.modes.size(); ++i) {
      const MrciMode& md = d.modes[i];
      if (!md.slow) {
        u += md.residue * xund[i][k];
      } else if (k >= md.phase) {
        const std::size_t j = (k - md.phase) / m;
        u += md.residue * xund[i][m * j];
      }
    }
    const double got = law.step(k, e[k]);
    worst = std::max(worst, std::abs(got - u));
    scale = std::max(scale, std::abs(u));
  }
  RecordProperty("rel_err", sci(worst / scale));
  EXPECT_LT(worst / scale, 1e-14);  // measured 1.4e-16
  // The schedule matters: the interlaced law is not C_D on the same errors.
  InterlacedLaw again = make(d);
  MrciDesign d1 = d;
  d1.ratio = 1;
  InterlacedLaw undivided = make(d1);
  double diff = 0;
  for (std::size_t k = 0; k < e.size(); ++k) diff = std::max(diff, std::abs(again.step(k, e[k]) - undivided.step(k, e[k])));
  EXPECT_GT(diff, 1e-3 * scale);
}

TEST(PacketBuffer, AppliesEntryAndHoldsTheLast) {
  oneshot::node::PacketBuffer<double, 3> buf(0.5);
  EXPECT_EQ(buf.value(7), 0.5);
  const double p[4] = {1, 2, 3, 4};
  ASSERT_EQ(buf.accept(10, p), oneshot::node::FrameStatus::kOk);
  EXPECT_EQ(buf.value(10), 1);
  EXPECT_EQ(buf.value(12), 3);
  EXPECT_EQ(buf.value(13), 4);
  EXPECT_FALSE(buf.exhausted(13));
  EXPECT_EQ(buf.value(40), 4);
  EXPECT_TRUE(buf.exhausted(14));
  EXPECT_EQ(buf.accept(9, p), oneshot::node::FrameStatus::kStale);  // older packet refused
}

}  // namespace
