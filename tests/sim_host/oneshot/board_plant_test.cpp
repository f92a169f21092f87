/// @file board_plant_test.cpp
/// @brief The board plant against an edge-by-edge oracle (Eigen exponential per PWM
///        segment, cost by quadrature), the latched PWM mode, and the noise statistics.
#include <gtest/gtest.h>

#include <random>

#include "oneshot/design/controller_synthesis.hpp"
#include "board_config.hpp"
#include "support/build_flavor.hpp"
#include "support/eigen_reference.hpp"

namespace oneshot::sim {
namespace {

using test::MatX;
using test::VecX;

/// Edge-by-edge oracle: walks every PWM edge, exact state by Eigen's exponential,
/// segment cost by 4-point Gauss–Legendre on 8 sub-panels of the exact trajectory.
class EdgeOracle {
 public:
  EdgeOracle(const design::PlantDescription& p, const design::DesignResult& d)
      : a_(test::to_eigen(p.a)), b_(test::to_eigen(p.b)), q1_(test::to_eigen(p.q1c)), x_(VecX::Zero(2)),
        period_(std::llround(1e9 / p.board.pwm_frequency_hz)), steps_(p.board.pwm_duty_steps),
        low_(p.board.pwm_low_volts[0]), high_(p.board.pwm_high_volts[0]), nx_(test::to_eigen(d.nx)) {}

  void set_duty(std::int32_t code) { code_ = code; }
  void set_setpoint(double r) { xref_ = nx_ * r; }

  void advance_to(std::int64_t t1) {
    while (now_ < t1) {
      const std::int64_t base = (now_ / period_) * period_;
      const std::int64_t fall = base + (static_cast<std::int64_t>(code_) * period_ + steps_ / 2) / steps_;
      std::int64_t next = base + period_;
      if (now_ < fall) next = fall;
      next = std::min(next, t1);
      const double v = now_ < fall ? high_ : low_;
      segment(static_cast<double>(next - now_) * 1e-9, v);
      now_ = next;
    }
  }
  const VecX& state() const { return x_; }
  double cost() const { return cost_; }

 private:
  VecX flow(double s, double v) const {
    MatX f = MatX::Zero(3, 3);
    f.topLeftCorner(2, 2) = a_;
    f.topRightCorner(2, 1) = b_;
    VecX z(3);
    z << x_, v;
    return (test::expm(f * s) * z).head(2);
  }
  void segment(double d, double v) {
    static const double gx[4] = {-0.8611363115940526, -0.3399810435848563, 0.3399810435848563, 0.8611363115940526};
    static const double gw[4] = {0.3478548451374538, 0.6521451548625461, 0.6521451548625461, 0.3478548451374538};
    const int panels = 8;
    for (int p = 0; p < panels; ++p)
      for (int k = 0; k < 4; ++k) {
        const double s = d / panels * (p + 0.5 + 0.5 * gx[k]);
        const VecX e = flow(s, v) - xref_;
        cost_ += 0.5 * d / panels * gw[k] * e.dot(q1_ * e);
      }
    x_ = flow(d, v);
  }

  MatX a_, b_, q1_;
  VecX x_;
  std::int64_t period_;
  std::int32_t steps_;
  double low_, high_;
  MatX nx_;
  VecX xref_ = VecX::Zero(2);
  std::int64_t now_ = 0;
  std::int32_t code_ = 0;
  double cost_ = 0;
};

TEST(BoardPlant, AggregatedPeriodsEqualEdgeByEdge) {
  // GIVEN the reference board without process noise
  const auto plant = design::reference_plant();
  const auto d = design::synthesize(plant);
  BoardOptions opt;
  opt.process_noise = false;
  BoardPlant<2, 1, 1> emu(circuit_config<2, 1, 1>(plant, d, opt), RandomStream(1, "noise"));
  EdgeOracle oracle(plant, d);
  std::mt19937_64 rng(5);
  std::uniform_int_distribution<std::int64_t> step(1, 60'000'000);  // up to 60 ms, ns resolution
  std::uniform_int_distribution<std::int32_t> duty(0, 2000);
  std::uniform_real_distribution<double> sp(-0.2, 0.2);
  std::int64_t t = 0;
  // WHEN both see the same duty writes, set-point changes and arbitrary event times
  // (an eighth of the events under the sanitizers: Eigen's exponential at -Og is 20x slower)
  const int events = test::sanitized_length(120, 8);
  for (int k = 0; k < events; ++k) {
    t += step(rng);
    emu.advance_to(engine::SimTime{t});
    oracle.advance_to(t);
    // THEN state and accumulated cost agree
    EXPECT_NEAR(emu.state()[0], oracle.state()[0], 1e-12 * (1 + std::fabs(oracle.state()[0]))) << "event " << k;
    EXPECT_NEAR(emu.state()[1], oracle.state()[1], 1e-12 * (1 + std::fabs(oracle.state()[1]))) << "event " << k;
    EXPECT_NEAR(emu.cost().state, oracle.cost(), 1e-10 * (1 + oracle.cost())) << "event " << k;
    const std::int32_t code = duty(rng);
    emu.set_duty(0, code);
    oracle.set_duty(code);
    if (k % 10 == 0) {
      Vector<double, 1> r;
      r[0] = sp(rng);
      emu.set_setpoint(r);
      oracle.set_setpoint(r[0]);
    }
  }
}

TEST(BoardPlant, LatchedDutyActsAtTheNextPeriod) {
  const auto plant = design::reference_plant();
  const auto d = design::synthesize(plant);
  BoardOptions opt;
  opt.process_noise = false;
  opt.update = PwmUpdate::kNextPeriod;
  BoardPlant<2, 1, 1> latched(circuit_config<2, 1, 1>(plant, d, opt), RandomStream(1, "noise"));
  opt.update = PwmUpdate::kImmediate;
  BoardPlant<2, 1, 1> immediate(circuit_config<2, 1, 1>(plant, d, opt), RandomStream(1, "noise"));
  latched.advance_to(engine::SimTime{10'010});  // inside the period [0, 50 µs)
  immediate.advance_to(engine::SimTime{10'010});
  latched.set_duty(0, 1500);
  EXPECT_EQ(latched.duty(0), 0);
  latched.advance_to(engine::SimTime{49'999});
  EXPECT_EQ(latched.duty(0), 0);
  latched.advance_to(engine::SimTime{50'000});
  EXPECT_EQ(latched.duty(0), 1500);
  // Same trajectory as an immediate write made at the period start.
  immediate.advance_to(engine::SimTime{50'000});
  immediate.set_duty(0, 1500);
  latched.advance_to(engine::SimTime{3'000'000});
  immediate.advance_to(engine::SimTime{3'000'000});
  EXPECT_NEAR(latched.state()[0], immediate.state()[0], 1e-15);
  EXPECT_NEAR(latched.state()[1], immediate.state()[1], 1e-15);
}

TEST(BoardPlant, ProcessNoiseHasTheExactCovariance) {
  const auto plant = design::reference_plant();
  const auto d = design::synthesize(plant);
  const auto cfg = circuit_config<2, 1, 1>(plant, d, BoardOptions{});
  const std::int64_t delta = 50'000'000;
  const int runs = 20000;
  // The PWM ripple itself moves the double integrator: subtract the noise-free trajectory.
  auto quiet_cfg = cfg;
  quiet_cfg.process_noise = false;
  BoardPlant<2, 1, 1> quiet(quiet_cfg, RandomStream(0, "noise"));
  quiet.set_duty(0, 1000);
  quiet.advance_to(engine::SimTime{delta});
  const VecX x_det = test::to_eigen(quiet.state());
  MatX sum = MatX::Zero(2, 2);
  for (int k = 0; k < runs; ++k) {
    BoardPlant<2, 1, 1> emu(cfg, RandomStream(static_cast<std::uint64_t>(k), "noise"));
    emu.set_duty(0, 1000);
    emu.advance_to(engine::SimTime{delta});
    const VecX x = test::to_eigen(emu.state()) - x_det;
    sum += x * x.transpose();
  }
  const MatX cov = sum / runs;
  const MatX qd = test::reference_triple(test::to_eigen(plant.a), test::to_eigen(plant.b), test::to_eigen(d.qc), 0.05).qd;
  // Sample covariance of 20000 draws: relative standard error ≈ sqrt(2/20000) = 1 %.
  EXPECT_NEAR(cov(0, 0), qd(0, 0), 0.05 * qd(0, 0));
  EXPECT_NEAR(cov(1, 1), qd(1, 1), 0.05 * qd(1, 1));
  EXPECT_NEAR(cov(0, 1), qd(0, 1), 0.08 * std::fabs(qd(0, 1)));
}

TEST(BoardPlant, ExpectedNoiseCostMatchesQuadrature) {
  const auto plant = design::reference_plant();
  const auto d = design::synthesize(plant);
  const BoardPlant<2, 1, 1> emu(circuit_config<2, 1, 1>(plant, d, BoardOptions{}), RandomStream(1, "noise"));
  for (std::int64_t delta : {1'000'000LL, 20'000'000LL, 50'000'000LL}) {
    // ∫₀^Δ tr(Q1c Q_d(s)) ds with Q_d by Eigen quadrature.
    const double dd = static_cast<double>(delta) * 1e-9;
    double ref = 0;
    const int n = 200;
    for (int i = 0; i < n; ++i) {
      const double s = dd * (i + 0.5) / n;
      ref += dd / n * (test::to_eigen(plant.q1c) * test::qd_by_quadrature(test::to_eigen(plant.a), test::to_eigen(d.qc), s, 20)).trace();
    }
    EXPECT_NEAR(emu.expected_noise_cost(engine::Duration{delta}), ref, 1e-4 * ref) << delta;
  }
}

TEST(BoardPlant, AdcQuantisesAndSaturates) {
  const auto plant = design::reference_plant();
  const auto d = design::synthesize(plant);
  BoardPlant<2, 1, 1> emu(circuit_config<2, 1, 1>(plant, d, BoardOptions{}), RandomStream(1, "noise"));
  Vector<double, 2> x;
  x[0] = 0.0;
  emu.set_state(x);
  EXPECT_EQ(emu.adc_code(0, 0.0), 2048);
  EXPECT_EQ(emu.adc_code(0, -0.0005), 2047);
  EXPECT_EQ(emu.adc_code(0, 5.0), 4095);
  EXPECT_EQ(emu.adc_code(0, -5.0), 0);
}

}  // namespace
}  // namespace oneshot::sim
