/// @file study_plant_shapes_test.cpp
/// @brief Plants of other shapes in a study file: a first-order plant inline runs the sampling
///        loops to its steady state with consistent filters; a plant embedded in a larger
///        instantiated shape runs its own run, to the bit; a 16-state plant runs the Kalman
///        loops; a plant measuring fewer outputs than states runs the filters (S refused); plants
///        past the limits (n 16, m 4, p 4) are refused naming the key.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <functional>
#include <random>
#include <string>

#include "ncs_loop.hpp"
#include "oneshot/engine/study_file.hpp"
#include "study_check.hpp"
#include "study_example.hpp"
#include "study_ncs_runner.hpp"
#include "study_ncs_sweep.hpp"
#include "study_plant_outputs.hpp"
#include "support/temp_files.hpp"

namespace oneshot::study {
namespace {

using test_support::inline_plant_of;

const test_support::StudyExample kInlineNcs("ncs.json");

/// ncs.json on a first-order plant inline: ẋ = −a x + b u, y = x (a = 4 /s, b = 8 /s, Q1c = 25,
/// the board's noise and converters for one output), the sampling loops I, S, SK, IK, its
/// first scenario (±0.2 V, T_r = 2 s).
constexpr double kA = 4;
constexpr double kB = 8;
void first_order(nlohmann::json& j) {
  nlohmann::json c = inline_plant_of("networked_board.json")["continuous"];
  c["states"] = {"x"};
  c["inputs"] = {"u"};
  c["outputs"] = {"x"};
  c["tracked_outputs"] = {"x"};
  c["A"] = {{-kA}};
  c["B"] = {{kB}};
  c["C"] = {{1.0}};
  c["Q1c"] = {{25.0}};
  c["Q2c"] = {{1.0}};
  c["Q_c"] = {{4e-6}};
  c["measurement_covariance"] = {{8e-5}};
  c["board"]["adc_min_volts"] = {-1.65};
  c["board"]["adc_max_volts"] = {1.65};
  j["plant"] = {{"continuous", c}};
  j["approaches"] = nlohmann::json::array();
  for (const char* k : {"I", "S", "SK", "IK"}) j["approaches"].push_back({{"name", k}, {"kind", k}});
  j["scenarios"] = {j["scenarios"][0]};
}

TEST(StudyPlantShapes, AFirstOrderPlantRunsTheSamplingLoopsToItsSteadyState) {
  const NcsStudy s = kInlineNcs.study(first_order, 2.0);
  ASSERT_EQ(s.ctx->plant().a.rows, 1U);
  ncs::Scenario sc = s.scenarios[0];
  const double r = sc.amplitude_volts;  // +A_r until T_r/2, then −A_r
  // I until the first change: it starts on the set-point without delay or noise (J = 0).
  ncs::Scenario half = sc;
  half.duration_s = sc.period_s / 2;
  EXPECT_NEAR(ncs::run(*s.ctx, ncs::Approach::kI, half, 1, {}).cost, 0.0, 1e-20);
  // Noise-free over a whole period: after the switch the loop settles where 0 = −a x + b u,
  // y = x tracks −A_r: x = −A_r, u = −a A_r / b (the closed-loop pole near −40 /s: settled to
  // rounding within the half wave). Not SK: its filter's observer (Q ≪ R: a small gain) and
  // the unmodelled delays leave it 5e-5 V off at the end of the half wave.
  ncs::RunOptions o;
  o.noise_free = true;
  o.trace_step_s = 0.01;
  for (ncs::Approach a : {ncs::Approach::kI, ncs::Approach::kS, ncs::Approach::kIK}) {
    const ncs::RunResult res = ncs::run(*s.ctx, a, sc, 3, o);
    ASSERT_FALSE(res.truth.empty());
    EXPECT_NEAR(res.truth.back().v[0], -r, 1e-9) << ncs::name(a);
    EXPECT_NEAR(res.setpoint.back().v[1], -kA * r / kB, 1e-9) << ncs::name(a);
    EXPECT_GT(res.cost, 0.0) << ncs::name(a);
  }
  // Refused on this shape, naming the field: the 2-state approaches and --analytic.
  kInlineNcs.expect_refused([](nlohmann::json& j) {
    first_order(j);
    j["approaches"].push_back({{"name", "AK"}, {"kind", "AK"}});
  }, "field 'approaches[4].kind': AK runs the board's plant");
  EXPECT_THROW(run_ncs_sweep(s, 2, 1, engine::Shard{}, true), engine::InputError);
}

TEST(StudyPlantShapes, TheFiltersOfAFirstOrderPlantAreConsistent) {
  // The NEES of IK (x(kh) against x̂_{k|k}, P_{k|k}; no delay) has mean n = 1 for a consistent
  // filter: the mean over seeds within a few standard errors of 1 (measured 0.86 ± 0.09 over
  // 12 seeds). SK's filter does not model the delays (its NEES is far above n, as on the board).
  const NcsStudy s = kInlineNcs.study(first_order, 4.0);
  for (ncs::Approach a : {ncs::Approach::kIK}) {
    double sum = 0, sum2 = 0;
    const int seeds = 12;
    for (int seed = 1; seed <= seeds; ++seed) {
      const ncs::RunResult res = ncs::run(*s.ctx, a, s.scenarios[0], static_cast<std::uint64_t>(seed), {});
      ASSERT_GT(res.nees_steps, 50U);
      sum += res.nees;
      sum2 += res.nees * res.nees;
    }
    const double mean = sum / seeds;
    const double se = std::sqrt(std::fmax(0.0, sum2 / seeds - mean * mean) / (seeds - 1));
    std::printf("%s: NEES %.4f (standard error %.4f over %d seeds)\n", ncs::name(a), mean, se, seeds);
    EXPECT_NEAR(mean, 1.0, 4 * se + 0.02) << ncs::name(a);
  }
}

/// The largest relative difference |a − b| / |b| (0 when both are 0).
double relative(double a, double b) { return a == b ? 0.0 : std::fabs(a - b) / std::fmax(std::fabs(a), std::fabs(b)); }

TEST(StudyPlantShapes, APlantEmbeddedInALargerShapeRunsItsOwnRun) {
  // The oracle: the padded parts are inert (A, B, C, Q_c, L, N_x, N_u, Φ − I, Γ, Q_d, P0 zero
  // there, R 1) and only the real dimensions draw noise, so the first-order plant (1, 1, 1) and
  // the board's (2, 1, 2) forced into the capacity shapes (6, 4, 4) and (16, 4, 4) give the
  // native shape's cost and NEES per seed. Measured: identical to the bit (relative difference
  // 0) for I, S, SK, IK, noisy and noise-free; the tolerance 1e-13 allows a few ulps of the
  // longer sums.
  const NcsStudy first = kInlineNcs.study(first_order, 2.0);
  const NcsStudy board = kInlineNcs.study([](nlohmann::json& j) {
    j["approaches"] = nlohmann::json::array();
    for (const char* k : {"I", "S", "SK", "IK"}) j["approaches"].push_back({{"name", k}, {"kind", k}});
    j["scenarios"] = {j["scenarios"][0]};
  }, 2.0);
  // The first-order plant with Q_c and R 1e-12 times smaller (R = 8e-17): the padded R's diagonal
  // follows the real R's scale, else the pad (of 1) would raise the norm the solve's singularity
  // test takes and every correction would be skipped as singular.
  const NcsStudy tiny = kInlineNcs.study([](nlohmann::json& j) {
    first_order(j);
    nlohmann::json& c = j["plant"]["continuous"];
    c["Q_c"] = {{4e-18}};
    c["measurement_covariance"] = {{8e-17}};
  }, 2.0);
  double worst = 0;
  for (const NcsStudy* s : {&first, &board, &tiny}) {
    for (const ncs::NcsShapeOf shape : {ncs::NcsShapeOf{6, 4, 4, true}, ncs::NcsShapeOf{16, 4, 4, true}}) {
      for (ncs::Approach a : {ncs::Approach::kI, ncs::Approach::kS, ncs::Approach::kSK, ncs::Approach::kIK}) {
        if (shape.n > ncs::kMaxStateFeedbackStates && (a == ncs::Approach::kI || a == ncs::Approach::kS)) continue;
        for (bool noise_free : {false, true}) {
          for (std::uint64_t seed = 1; seed <= 3; ++seed) {
            ncs::RunOptions native;
            native.noise_free = noise_free;
            ncs::RunOptions padded = native;
            padded.force_shape = shape;
            const ncs::RunResult r0 = ncs::run(*s->ctx, a, s->scenarios[0], seed, native);
            const ncs::RunResult r1 = ncs::run(*s->ctx, a, s->scenarios[0], seed, padded);
            ASSERT_GT(r0.cost, 0.0);
            const double d = std::fmax(relative(r1.cost, r0.cost), relative(r1.nees, r0.nees));
            worst = std::fmax(worst, d);
            EXPECT_LE(d, 1e-13) << ncs::name(a) << " n = " << s->ctx->states() << " in " << shape.n << " noise-free " << noise_free;
            EXPECT_EQ(r1.nees_steps, r0.nees_steps);
            EXPECT_EQ(r1.commands, r0.commands);
            EXPECT_EQ(r1.faults, r0.faults);
          }
        }
      }
    }
  }
  std::printf("padded vs native: largest relative difference %.3g\n", worst);
  // A shape that does not hold the plant is refused.
  ncs::RunOptions small;
  small.force_shape = ncs::NcsShapeOf{1, 1, 1, true};
  EXPECT_THROW(ncs::run(*board.ctx, ncs::Approach::kIK, board.scenarios[0], 1, small), std::invalid_argument);
}

/// A seeded stable plant of n = 16 states, m = 2 inputs, p = 3 outputs inline, y1, y2 tracked
/// (the set-point on y1), IK and SK. `fast`: A = −diag(25 … 40) + off-diagonal U(−0.5, 0.5)
/// (every mode faster than 17 /s by Gershgorin), h = 50 ms; else A = −diag(0.5 … 2) +
/// off-diagonal U(−0.05, 0.05), h = 10 ms: |λ|h ≤ 0.03, so the design's constant per-step
/// Q = Q_c h is the exact Q_d(h) to 3 % (with fast modes Q_c h overstates Q_d ≈ Q_c/(2|λ|) and
/// the NEES falls far below n: 6.5 measured for the fast plant).
void sixteen_states(nlohmann::json& j, bool fast) {
  constexpr std::size_t n = 16, m = 2, p = 3;
  std::mt19937_64 gen(16);
  std::uniform_real_distribution<double> u(-0.5, 0.5);
  nlohmann::json a = nlohmann::json::array(), b = nlohmann::json::array(), c = nlohmann::json::array(), q = nlohmann::json::array();
  for (std::size_t i = 0; i < n; ++i) {
    nlohmann::json ra = nlohmann::json::array(), rb = nlohmann::json::array(), rq = nlohmann::json::array();
    for (std::size_t k = 0; k < n; ++k) {
      ra.push_back(i == k ? (fast ? -25.0 - static_cast<double>(i) : -0.5 - 0.1 * static_cast<double>(i))
                          : (fast ? 1.0 : 0.1) * u(gen));
      rq.push_back(i == k ? 1.0 : 0.0);
    }
    for (std::size_t k = 0; k < m; ++k) rb.push_back(4 * u(gen));
    a.push_back(ra);
    b.push_back(rb);
    q.push_back(rq);
  }
  for (std::size_t i = 0; i < p; ++i) {
    nlohmann::json rc = nlohmann::json::array();
    for (std::size_t k = 0; k < n; ++k) rc.push_back(u(gen));
    c.push_back(rc);
  }
  nlohmann::json pl = inline_plant_of("networked_board.json")["continuous"];
  pl["name"] = "sixteen-states";
  pl["states"] = nlohmann::json::array();
  for (std::size_t i = 0; i < n; ++i) pl["states"].push_back("x" + std::to_string(i));
  pl["inputs"] = {"u1", "u2"};
  pl["outputs"] = {"y1", "y2", "y3"};
  pl["tracked_outputs"] = {"y1", "y2"};  // one per input (the set-point on y1, y2's 0)
  pl["A"] = a;
  pl["B"] = b;
  pl["C"] = c;
  pl["Q1c"] = q;
  pl["Q2c"] = {{1.0, 0.0}, {0.0, 1.0}};
  nlohmann::json qc = q;
  for (auto& row : qc)
    for (auto& v : row) v = v.get<double>() * 1e-4;
  pl["Q_c"] = qc;
  pl["measurement_covariance"] = {{1e-6, 0.0, 0.0}, {0.0, 1e-6, 0.0}, {0.0, 0.0, 1e-6}};
  pl["board"]["pwm_low_volts"] = {-1000.0, -1000.0};  // no saturation: the steady state is linear
  pl["board"]["pwm_high_volts"] = {1000.0, 1000.0};
  const int h_us = fast ? 50000 : 10000;
  pl["period_us"] = h_us;
  j["nodes"][0]["period_us"] = h_us;
  j["nodes"][2]["period_us"] = h_us;
  pl["board"]["adc_min_volts"] = {-5.0, -5.0, -5.0};
  pl["board"]["adc_max_volts"] = {5.0, 5.0, 5.0};
  j["plant"] = {{"continuous", pl}};
  j["approaches"] = nlohmann::json::array();
  for (const char* k : {"IK", "SK"}) j["approaches"].push_back({{"name", k}, {"kind", k}});
  j["scenarios"] = {j["scenarios"][0]};
}

TEST(StudyPlantShapes, ASixteenStatePlantRunsTheKalmanLoops) {
  const NcsStudy s = kInlineNcs.study([](nlohmann::json& j) { sixteen_states(j, true); }, 4.0);
  const NcsStudy slow = kInlineNcs.study([](nlohmann::json& j) { sixteen_states(j, false); }, 4.0);
  ASSERT_EQ(s.ctx->states(), 16U);
  ASSERT_EQ(s.approaches[0], ncs::Approach::kIK);  // I cannot run n > 6: IK is the reference
  const ncs::Scenario& sc = s.scenarios[0];
  const double r = sc.amplitude_volts;  // +A_r until T_r/2, then −A_r
  // Noise-free, IK settles after the switch where A x + B u = 0 with the tracked output at −A_r:
  // x = N_x (−A_r), u = N_u (−A_r) of the design (every mode faster than 17 /s: e^{−17·3 s} of
  // the step by the end, far below 1e-9).
  ncs::RunOptions o;
  o.noise_free = true;
  o.trace_step_s = 0.01;
  const ncs::RunResult quiet = ncs::run(*s.ctx, ncs::Approach::kIK, sc, 3, o);
  ASSERT_FALSE(quiet.truth.empty());
  const std::size_t out = s.ctx->design().tracked_outputs[0];
  for (std::size_t i = 0; i < 2; ++i) EXPECT_NEAR(quiet.truth.back().v[i], -r * s.ctx->design().nx(i, out), 1e-9) << i;
  EXPECT_NEAR(quiet.setpoint.back().v[1], -r * s.ctx->design().nu(0, out), 1e-9);
  // Noisy (the slow plant): finite costs; IK's NEES (x(kh) against x̂_{k|k}, P_{k|k}, no delay)
  // has mean n = 16 for a consistent filter: within four standard errors (+0.5, the 3 % of
  // Q_c h) over 8 seeds (measured in the test's output). SK's filter ignores the delays: finite only.
  double sum = 0, sum2 = 0;
  const int seeds = 8;
  for (int seed = 1; seed <= seeds; ++seed) {
    const ncs::RunResult ik = ncs::run(*slow.ctx, ncs::Approach::kIK, slow.scenarios[0], static_cast<std::uint64_t>(seed), {});
    const ncs::RunResult sk = ncs::run(*slow.ctx, ncs::Approach::kSK, slow.scenarios[0], static_cast<std::uint64_t>(seed), {});
    EXPECT_TRUE(std::isfinite(ik.cost) && ik.cost > 0);
    EXPECT_TRUE(std::isfinite(sk.cost) && sk.cost > 0);
    EXPECT_TRUE(std::isfinite(sk.nees));
    ASSERT_GT(ik.nees_steps, 50U);
    sum += ik.nees;
    sum2 += ik.nees * ik.nees;
  }
  const double mean = sum / seeds;
  const double se = std::sqrt(std::fmax(0.0, sum2 / seeds - mean * mean) / (seeds - 1));
  std::printf("IK on n = 16: NEES %.4f (standard error %.4f over %d seeds)\n", mean, se, seeds);
  EXPECT_NEAR(mean, 16.0, 4 * se + 0.5);
  // I does not run n > 6 (its state does not fit a frame), naming the approach.
  kInlineNcs.expect_refused([](nlohmann::json& j) {
    sixteen_states(j, true);
    j["approaches"].push_back({{"name", "I"}, {"kind", "I"}});
  }, "field 'approaches[2].kind': I sends the state x in one sensor frame");
  kInlineNcs.expect_refused([](nlohmann::json& j) {
    sixteen_states(j, true);
    j["approaches"][0] = {{"name", "SK"}, {"kind", "SK"}};
    j["approaches"][1] = {{"name", "IK"}, {"kind", "IK"}};
  }, "field 'approaches[0].kind': the first approach must be I");
}

const test_support::StudyExample kMotor("dc_motor_position.json");

TEST(StudyPlantShapes, APlantMeasuringLessThanItsStatesRunsTheFiltersNotS) {
  // The DC-motor servo measures θ only (n = 3, p = 1): I feeds x back, SK and IK filter θ; S
  // (y fed back as x) needs C = I and is refused naming the approach.
  const NcsStudy s = kMotor.study([](nlohmann::json&) {}, 4.0);  // past the first change at T_r/2 = 2 s
  ASSERT_EQ(s.ctx->outputs(), 1U);
  EXPECT_FALSE(s.ctx->identity_output());
  for (ncs::Approach a : {ncs::Approach::kI, ncs::Approach::kSK, ncs::Approach::kIK}) {
    const ncs::RunResult res = ncs::run(*s.ctx, a, s.scenarios[0], 1, {});
    EXPECT_TRUE(std::isfinite(res.cost) && res.cost > 0) << ncs::name(a);
  }
  kMotor.expect_refused([](nlohmann::json& j) { j["approaches"].push_back({{"name", "S"}, {"kind", "S"}}); },
                        "field 'approaches[3].kind': S feeds y back as the state: it needs C = I");
  kMotor.expect_refused([](nlohmann::json& j) { j["approaches"].push_back({{"name", "AK"}, {"kind", "AK"}}); },
                        "field 'approaches[3].kind': AK runs the board's plant");
}

TEST(StudyPlantShapes, APlantLargerThanTheLimitsIsRefusedNamingTheKey) {
  // n ≤ 16, m ≤ 4, p ≤ 4: one more state, input or output is refused naming A, B or C, with
  // the limits.
  const auto sized = [](std::size_t n, std::size_t m, std::size_t p) {
    return [n, m, p](nlohmann::json& j) {
      const auto mat = [](std::size_t r, std::size_t c, bool eye) {
        nlohmann::json x = nlohmann::json::array();
        for (std::size_t i = 0; i < r; ++i) {
          nlohmann::json row = nlohmann::json::array();
          for (std::size_t k = 0; k < c; ++k) row.push_back(eye && i == k ? -1.0 : 0.0);
          x.push_back(row);
        }
        return x;
      };
      j["plant"] = {{"continuous", {{"A", mat(n, n, true)}, {"B", mat(n, m, false)}, {"C", mat(p, n, false)},
                                     {"Q_c", mat(n, n, false)}, {"Q1c", mat(n, n, false)}, {"Q2c", mat(m, m, false)}}}};
    };
  };
  kInlineNcs.expect_refused(sized(17, 1, 1), "field 'plant.continuous.A': dimensions n = 17, m = 1, p = 1, w = 0 exceed the "
                                             "supported limits (kMaxStates 16, kMaxInputs 4, kMaxOutputs 4");
  kInlineNcs.expect_refused(sized(3, 5, 1), "field 'plant.continuous.B': dimensions n = 3, m = 5");
  kInlineNcs.expect_refused(sized(3, 1, 5), "field 'plant.continuous.C': dimensions n = 3, m = 1, p = 5");
  // A discrete plant names Phi and Gamma.
  const auto discrete = [&](std::size_t n, std::size_t m) {
    return [n, m, sized](nlohmann::json& j) {
      sized(n, m, 1)(j);
      nlohmann::json c = j["plant"]["continuous"];
      j["plant"] = {{"discrete", {{"Phi", c["A"]}, {"Gamma", c["B"]}, {"C", c["C"]}, {"Q", c["Q_c"]}, {"period_us", 50000}}}};
    };
  };
  kInlineNcs.expect_refused(discrete(17, 1), "field 'plant.discrete.Phi': dimensions n = 17");
  kInlineNcs.expect_refused(discrete(3, 5), "field 'plant.discrete.Gamma': dimensions n = 3, m = 5");
}

}  // namespace
}  // namespace oneshot::study
