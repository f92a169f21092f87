/// @file plants_test.cpp
/// @brief Continuous and discrete plants: exact propagation and cost against Eigen and
///        quadrature, noise with the exact covariance, bridged traces that leave the run
///        alone, the discrete latch/step order, and the dimension check of plain-matrix models.
#include <gtest/gtest.h>

#include <cstring>
#include <thread>


#include "oneshot/engine/continuous_plant.hpp"
#include "oneshot/engine/discrete_plant.hpp"
#include "oneshot/engine/plant_cache_pool.hpp"
#include "oneshot/engine/plant_model.hpp"
#include "support/eigen_reference.hpp"
#include "support/expect_error.hpp"

namespace oneshot::engine {
namespace {

using test::MatX;
using test::VecX;

/// A damped oscillator with an integrator (n = 3, m = 1, p = 1, one disturbance input).
ContinuousPlantConfig<3, 1, 1, 1> oscillator(bool noise) {
  ContinuousPlantConfig<3, 1, 1, 1> c;
  const double a[9] = {0, 1, 0, -4, -0.4, 0, 1, 0, 0};
  const double b[3] = {0, 1, 0};
  const double bw[3] = {0, 0.5, 0.2};
  c.a = Matrix<double, 3, 3>(a);
  c.b = Matrix<double, 3, 1>(b);
  c.bw = Matrix<double, 3, 1>(bw);
  c.c(0, 2) = 1;
  c.qc(0, 0) = 1e-3;
  c.qc(1, 1) = 2e-3;
  c.qc(2, 2) = 5e-4;
  c.q1c = Matrix<double, 3, 3>::identity();
  c.q2c(0, 0) = 0.5;
  c.process_noise = noise;
  return c;
}

/// Exact flow of ż = F z (z = [x; u; d]) by Eigen, cost ∫ eᵀQ1c e by 4-point Gauss–Legendre
/// (measured agreement: state 1.7e-16, cost 1.0e-15 relative; tolerances 2e-15 and 1e-14).
struct Oracle {
  MatX f = MatX::Zero(5, 5);
  VecX x = VecX::Zero(3);
  double cost = 0;
  explicit Oracle(const ContinuousPlantConfig<3, 1, 1, 1>& c) {
    f.topLeftCorner(3, 3) = test::to_eigen(c.a);
    f.block(0, 3, 3, 1) = test::to_eigen(c.b);
    f.block(0, 4, 3, 1) = test::to_eigen(c.bw);
  }
  VecX flow(double s, double u, double d) const {
    VecX z(5);
    z << x, u, d;
    return (test::expm(f * s) * z).head(3);
  }
  void advance(double dt, double u, double d, const VecX& xref, double uref, double q2) {
    static const double gx[4] = {-0.8611363115940526, -0.3399810435848563, 0.3399810435848563, 0.8611363115940526};
    static const double gw[4] = {0.3478548451374538, 0.6521451548625461, 0.6521451548625461, 0.3478548451374538};
    for (int p = 0; p < 16; ++p)
      for (int k = 0; k < 4; ++k) {
        const double s = dt / 16 * (p + 0.5 + 0.5 * gx[k]);
        const VecX e = flow(s, u, d) - xref;
        cost += 0.5 * dt / 16 * gw[k] * e.squaredNorm();
      }
    cost += q2 * (u - uref) * (u - uref) * dt;
    x = flow(dt, u, d);
  }
};

TEST(ContinuousPlant, ExactPropagationAndCostAgainstEigen) {
  const auto cfg = oscillator(false);
  ContinuousPlant<3, 1, 1, 1> plant(cfg, RandomStream(1, "p"));
  Oracle oracle(cfg);
  RandomStream rng(4, "events");
  SimTime t{0};
  Vector<double, 1> u;
  Vector<double, 1> d;
  // Reference x_ref = [0, 0, r] with u_ref = 0: an equilibrium (third state is a pure integrator of x1).
  Vector<double, 3> xref;
  for (int k = 0; k < 60; ++k) {
    const Duration dt{rng.uniform_int(1, 80'000'000)};
    oracle.advance(to_seconds(dt), u[0], d[0], test::to_eigen(xref), 0, 0.5);
    t += dt;
    plant.advance_to(t);
    for (Eigen::Index i = 0; i < 3; ++i) {
      EXPECT_NEAR(plant.state()[static_cast<std::size_t>(i)], oracle.x[i], 2e-15 * (1 + std::fabs(oracle.x[i]))) << k;
    }
    EXPECT_NEAR(plant.cost().total(), oracle.cost, 1e-14 * (1 + oracle.cost)) << k;
    u[0] = rng.uniform(-1, 1);
    plant.set_input(u);
    if (k % 7 == 0) d[0] = rng.uniform(-0.5, 0.5);
    plant.set_disturbance(d);
    if (k % 10 == 0) {
      xref[2] = rng.uniform(-1, 1);
      plant.set_reference(xref, Vector<double, 1>{});
    }
  }
  Vector<double, 3> bad;
  bad[0] = 1;  // ẋ2 = −4 x1 ≠ 0: not an equilibrium with u_ref = 0
  EXPECT_THROW(plant.set_reference(bad, Vector<double, 1>{}), std::invalid_argument);
}

TEST(ContinuousPlant, AnEmbeddedPlantDrawingItsActiveStatesOnlyIsItsOwnRun) {
  // The oracle: ẋ = −2x + u with Q_c = 0.3, as a plant of its own (1 state) and zero padded in
  // 3 states (A, B, C, Q_c, Q1c 0 on the padded ones) drawing the first normal only
  // (active_states = 1): the same noise draws, so the same state, cost and trace; the padded
  // states stay 0. Measured: identical to the bit; the tolerance allows 1e-15 relative.
  ContinuousPlantConfig<1, 1, 1, 1> own;
  own.a(0, 0) = -2;
  own.b(0, 0) = 1;
  own.c(0, 0) = 1;
  own.qc(0, 0) = 0.3;
  own.q1c(0, 0) = 1;
  own.q2c(0, 0) = 0.5;
  ContinuousPlantConfig<3, 1, 1, 1> padded;
  padded.a(0, 0) = -2;
  padded.b(0, 0) = 1;
  padded.c(0, 0) = 1;
  padded.qc(0, 0) = 0.3;
  padded.q1c(0, 0) = 1;
  padded.q2c(0, 0) = 0.5;
  padded.active_states = 1;
  ContinuousPlant<1, 1, 1, 1> a(own, RandomStream(7, "noise"));
  ContinuousPlant<3, 1, 1, 1> b(padded, RandomStream(7, "noise"));
  a.record_trace(Duration{3'000'000}, RandomStream(7, "trace"));
  b.record_trace(Duration{3'000'000}, RandomStream(7, "trace"));
  RandomStream rng(5, "events");
  SimTime t{0};
  for (int k = 0; k < 200; ++k) {
    t += Duration{rng.uniform_int(1, 20'000'000)};
    a.advance_to(t);
    b.advance_to(t);
    EXPECT_NEAR(b.state()[0], a.state()[0], 1e-15 * (1 + std::fabs(a.state()[0]))) << k;
    EXPECT_EQ(b.state()[1], 0.0);
    EXPECT_EQ(b.state()[2], 0.0);
    Vector<double, 1> u;
    u[0] = rng.uniform(-1, 1);
    a.set_input(u);
    b.set_input(u);
  }
  EXPECT_NEAR(b.cost().total(), a.cost().total(), 1e-15 * a.cost().total());
  ASSERT_EQ(b.trace().size(), a.trace().size());
  for (std::size_t i = 0; i < a.trace().size(); ++i) {
    EXPECT_NEAR(b.trace()[i].x[0], a.trace()[i].x[0], 1e-15 * (1 + std::fabs(a.trace()[i].x[0]))) << i;
    EXPECT_EQ(b.trace()[i].x[1], 0.0) << i;
  }
}

TEST(ContinuousPlant, NoiseHasTheExactCovarianceAndTracesDoNotChangeTheRun) {
  const auto cfg = oscillator(true);
  const Duration delta{40'000'000};
  const MatX qd = test::qd_by_quadrature(test::to_eigen(cfg.a), test::to_eigen(cfg.qc), to_seconds(delta), 50);
  const MatX qd_half = test::qd_by_quadrature(test::to_eigen(cfg.a), test::to_eigen(cfg.qc), to_seconds(delta) / 2, 50);
  MatX end = MatX::Zero(3, 3);
  MatX mid = MatX::Zero(3, 3);
  const int runs = 20000;
  for (int k = 0; k < runs; ++k) {
    ContinuousPlant<3, 1, 1, 1> traced(cfg, RandomStream(static_cast<std::uint64_t>(k), "noise"));
    ContinuousPlant<3, 1, 1, 1> plain(cfg, RandomStream(static_cast<std::uint64_t>(k), "noise"));
    traced.record_trace(delta / 2, RandomStream(static_cast<std::uint64_t>(k), "trace"));
    traced.advance_to(delta);
    plain.advance_to(delta);
    ASSERT_EQ(traced.state()[0], plain.state()[0]);  // the trace draws from its own stream
    ASSERT_EQ(traced.cost().total(), plain.cost().total());
    const VecX x = test::to_eigen(plain.state());
    const VecX xm = test::to_eigen(traced.trace()[1].x);  // bridged point at Δ/2 (state started at 0)
    end += x * x.transpose() / runs;
    mid += xm * xm.transpose() / runs;
    ASSERT_NEAR(traced.trace()[2].x[1], plain.state()[1], 1e-15);  // the trace point at the event is the state
  }
  // 20 000 draws: relative standard error of a variance ≈ 1 %; of a covariance a few %.
  for (Eigen::Index i = 0; i < 3; ++i) {
    EXPECT_NEAR(end(i, i), qd(i, i), 0.05 * qd(i, i)) << i;
    EXPECT_NEAR(mid(i, i), qd_half(i, i), 0.05 * qd_half(i, i)) << i;  // unconditional law of a bridge point
  }
  EXPECT_NEAR(end(0, 1), qd(0, 1), 0.1 * std::sqrt(qd(0, 0) * qd(1, 1)));
}

/// Bytes of a matrix.
template <std::size_t R, std::size_t C>
bool same_bytes(const Matrix<double, R, C>& x, const Matrix<double, R, C>& y) {
  for (std::size_t i = 0; i < R; ++i)
    for (std::size_t j = 0; j < C; ++j)
      if (std::memcmp(&x(i, j), &y(i, j), sizeof(double)) != 0) return false;
  return true;
}

/// A run of 300 random intervals (whole µs up to 50 ms, often repeated), inputs and a trace.
struct PlantRun {
  Vector<double, 3> x;
  double cost = 0;
  double trace_x0 = 0;
};
PlantRun run_plant(const ContinuousPlantConfig<3, 1, 1, 1>& cfg, std::uint64_t seed, PlantCachePool<3, 2>* pool) {
  ContinuousPlant<3, 1, 1, 1> plant(cfg, RandomStream(seed, "p"), pool);
  plant.record_trace(Duration{7'000'000}, RandomStream(seed, "trace"));
  RandomStream rng(seed, "events");
  SimTime t{0};
  for (int k = 0; k < 300; ++k) {
    t += Duration{1000 * rng.uniform_int(1, 400)};
    plant.advance_to(t);
    Vector<double, 1> u;
    u[0] = rng.uniform(-1, 1);
    plant.set_input(u);
  }
  return {plant.state(), plant.cost().total(), plant.trace().back().x[0]};
}

TEST(PlantCachePool, RunsWithThePoolAreTheRunsWithTheirOwnCachesBitForBit) {
  PlantCachePool<3, 2> pool;
  for (bool noise : {true, false})
    for (std::uint64_t seed = 1; seed <= 3; ++seed) {  // later seeds hit what earlier ones computed
      const PlantRun own = run_plant(oscillator(noise), seed, nullptr);
      const PlantRun shared = run_plant(oscillator(noise), seed, &pool);
      EXPECT_TRUE(same_bytes(own.x, shared.x)) << seed;
      EXPECT_EQ(std::memcmp(&own.cost, &shared.cost, sizeof(double)), 0) << seed;
      EXPECT_EQ(std::memcmp(&own.trace_x0, &shared.trace_x0, sizeof(double)), 0) << seed;
    }
}

TEST(PlantCachePool, AHitReturnsTheSameBytesAndDifferentPlantsNeverShare) {
  PlantCachePool<3, 2> pool;
  const auto cfg = oscillator(true);
  Matrix<double, 3, 2> b;
  b.set_block<0, 0>(cfg.b);
  b.set_block<0, 1>(cfg.bw);
  const auto c1 = pool.take(cfg.a, b, cfg.qc, cfg.q1c);
  const auto c2 = pool.take(cfg.a, b, cfg.qc, cfg.q1c);
  EXPECT_EQ(c1.segments, c2.segments);
  EXPECT_EQ(c1.noise, c2.noise);
  ExactSegmentCache<3, 2> own(cfg.a, b, cfg.q1c);
  ProcessNoise<3> own_noise(cfg.a, cfg.qc, cfg.q1c);
  for (std::int64_t d : {1'000, 2'345'000, 50'000'000}) {
    const auto miss = c1.segments->get(d);  // a copy: the first call computes it
    const auto& hit = c2.segments->get(d);
    const auto& mine = own.get(d);
    EXPECT_TRUE(same_bytes(miss.phi, hit.phi) && same_bytes(miss.gamma, hit.gamma) && same_bytes(miss.g, hit.g)) << d;
    EXPECT_TRUE(same_bytes(mine.phi, hit.phi) && same_bytes(mine.gamma, hit.gamma) && same_bytes(mine.g, hit.g)) << d;
    EXPECT_TRUE(same_bytes(own_noise.interval_covariance(Duration{d}), c2.noise->interval_covariance(Duration{d}))) << d;
  }
  // Another noise scale: the same interval maps, other noise terms; another A, B or Q1c: others.
  const auto scaled = pool.take(cfg.a, b, cfg.qc * 4.0, cfg.q1c);
  EXPECT_EQ(scaled.segments, c1.segments);
  EXPECT_NE(scaled.noise, c1.noise);
  Matrix<double, 3, 3> a2 = cfg.a;
  a2(1, 1) = -0.5;
  const auto other_a = pool.take(a2, b, cfg.qc, cfg.q1c);
  EXPECT_NE(other_a.segments, c1.segments);
  EXPECT_NE(other_a.noise, c1.noise);
  Matrix<double, 3, 2> b2 = b;
  b2(2, 1) = 0.3;
  EXPECT_NE(pool.take(cfg.a, b2, cfg.qc, cfg.q1c).segments, c1.segments);
  EXPECT_NE(pool.take(cfg.a, b, cfg.qc, cfg.q1c * 2.0).segments, c1.segments);
  Matrix<double, 3, 3> a_negative_zero = cfg.a;
  a_negative_zero(0, 0) = -0.0;  // the same value, other bytes: kept apart
  EXPECT_NE(pool.take(a_negative_zero, b, cfg.qc, cfg.q1c).segments, c1.segments);
  // Another thread has its own caches of the same plant.
  std::shared_ptr<ExactSegmentCache<3, 2>> there;
  std::thread([&] { there = pool.take(cfg.a, b, cfg.qc, cfg.q1c).segments; }).join();
  EXPECT_NE(there, c1.segments);
  // Bounded: at most kPlantsPerThread of each kind per thread; one taken before stays usable.
  for (int k = 0; k < 10; ++k) {
    Matrix<double, 3, 3> ak = cfg.a;
    ak(1, 0) = -4.0 - k;
    pool.take(ak, b, cfg.qc, cfg.q1c);
  }
  // This thread: a full shelf of each kind; the other thread: its one plant's two caches.
  EXPECT_EQ(pool.size(), (2 * PlantCachePool<3, 2>::kPlantsPerThread + 2));
  // A plant without process noise takes no noise cache.
  EXPECT_EQ(pool.take(cfg.a, b, cfg.qc, cfg.q1c, false).noise, nullptr);
  // The entry counts follow the byte budget within their bounds.
  using Pool = PlantCachePool<3, 2>;
  EXPECT_EQ(Pool::entries_for(1), Pool::kMaxEntries);
  EXPECT_EQ(Pool::entries_for(Pool::kCacheBytes), Pool::kMinEntries);
  EXPECT_LE(Pool::segment_entries() * sizeof(ExactSegment<3, 2>), Pool::kCacheBytes);
  EXPECT_LE((PlantCachePool<16, 8>::segment_entries() * sizeof(ExactSegment<16, 8>)), 2 * Pool::kCacheBytes);
  EXPECT_TRUE(same_bytes(c1.segments->get(1'000).phi, own.get(1'000).phi));
}

TEST(DiscretePlant, InputsLatchAtTheEndOfTheInstantAndStepsRunFirst) {
  DiscretePlantConfig<2, 1, 1, 1> c;
  const double phi[4] = {1, 0.1, 0, 0.9};
  c.phi = Matrix<double, 2, 2>(phi);
  c.gamma(1, 0) = 1;
  c.c(0, 0) = 1;
  c.q1 = Matrix<double, 2, 2>::identity();
  c.q2(0, 0) = 2;
  c.period = Duration{10'000'000};
  c.process_noise = false;
  DiscretePlant<2, 1, 1, 1> plant(c, RandomStream(1, "w"));
  Kernel k(1);
  attach_discrete_plant(k, plant, Duration{30'000'000});
  std::vector<double> seen;
  Vector<double, 1> u;
  const HandlerId sample = k.add_handler("sample", [&](std::uint64_t) { seen.push_back(plant.state()[1]); });
  const HandlerId act = k.add_handler("act", [&](std::uint64_t v) {
    u[0] = static_cast<double>(v);
    plant.set_input(u);
  });
  k.schedule(Duration{0}, EventClass::kActuation, act, 1);           // step 0 uses 1
  k.schedule(Duration{15'000'000}, EventClass::kCompute, act, 2);    // mid-period: acts from step 2
  k.schedule(Duration{10'000'000}, EventClass::kSample, sample, 0);  // sees x_1
  k.schedule(Duration{20'000'000}, EventClass::kSample, sample, 0);  // sees x_2
  k.run_until(Duration{30'000'000});
  ASSERT_EQ(plant.step_index(), 3);
  ASSERT_EQ(seen.size(), 2U);
  EXPECT_DOUBLE_EQ(seen[0], 1.0);              // x2_1 = 0.9·0 + 1
  EXPECT_DOUBLE_EQ(seen[1], 0.9 * 1.0 + 1.0);  // step 1 still used 1 (the write came after its latch)
  EXPECT_DOUBLE_EQ(plant.state()[1], 0.9 * 1.9 + 2.0);
  // Cost Σ e_kᵀQ1 e_k + 2 u_k²: steps 0, 1, 2 with u = 1, 1, 2.
  const double x1_1 = 0, x1_2 = 0.1 * 1.0, x2_1 = 1.0, x2_2 = 1.9;
  EXPECT_DOUBLE_EQ(plant.cost().total(), 0 + (x1_1 * x1_1 + x2_1 * x2_1) + (x1_2 * x1_2 + x2_2 * x2_2) + 2 * (1 + 1 + 4));
}

TEST(PlantModel, DimensionsMustMatchTheStudy) {
  ContinuousModel m;
  m.a = DenseMatrix::zeros(3, 3);
  m.b = DenseMatrix::zeros(3, 1);
  m.c = DenseMatrix::zeros(1, 3);
  m.qc = DenseMatrix::zeros(3, 3);
  test::expect_error_naming<std::invalid_argument>([&] { make_continuous_config<2, 1, 2, 1>(m, "ncs"); },
                                                   {"plant has n = 3, m = 1, p = 1", "study 'ncs' expects n = 2, m = 1, p = 2"});
  const auto c = make_continuous_config<3, 1, 1, 1>(m, "x");  // B_w absent: zero
  EXPECT_EQ(c.bw(2, 0), 0.0);
}

}  // namespace
}  // namespace oneshot::engine
