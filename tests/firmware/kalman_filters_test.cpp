/// @file kalman_filters_test.cpp
/// @brief Half, complete and standard filters and the deadbeat observer against the
///        brief's equations written with Eigen, on long random irregular τ sequences.
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <random>

#include "oneshot/complete_kalman.hpp"
#include "oneshot/deadbeat_observer.hpp"
#include "oneshot/design/controller_synthesis.hpp"
#include "oneshot/design/fixed_size.hpp"
#include "oneshot/generated/plant_tables.hpp"
#include "oneshot/half_kalman.hpp"
#include "oneshot/standard_kalman.hpp"
#include "filter_cases.hpp"
#include "support/eigen_reference.hpp"
#include "support/test_plants.hpp"

namespace oneshot {
namespace {

using generated::PlantConstants;
using generated::PlantStructure;

/// True plant driven by the same jobs: exact discretization, process and ADC-like noise.
class TruePlant {
 public:
  TruePlant(const design::PlantDescription& plant, const design::DesignResult& d, std::uint64_t seed)
      : a_(test::to_eigen(plant.a)), b_(test::to_eigen(plant.b)), c_(test::to_eigen(plant.c)),
        qc_(test::to_eigen(d.qc)), r_sigma_(std::sqrt(plant.measurement_covariance(0, 0))), rng_(seed),
        x_(test::VecX::Zero(a_.rows())) {}

  void advance(std::int32_t t_us, const test::VecX& u) {
    const test::Triple t = test::reference_triple(a_, b_, qc_, t_us * 1e-6);
    const Eigen::LLT<test::MatX> llt(t.qd + test::MatX::Identity(x_.size(), x_.size()) * 1e-30);
    test::VecX w(x_.size());
    for (Eigen::Index i = 0; i < w.size(); ++i) w[i] = normal_(rng_);
    x_ = t.phi * x_ + t.gamma * u + llt.matrixL() * w;
  }
  test::VecX measure() { return c_ * x_ + test::VecX::Constant(c_.rows(), r_sigma_ * normal_(rng_)); }
  const test::VecX& state() const { return x_; }

 private:
  test::MatX a_, b_, c_, qc_;
  double r_sigma_;
  std::mt19937_64 rng_;
  std::normal_distribution<double> normal_{0.0, 1.0};
  test::VecX x_;
};

using Variant = test::FilterVariant;

struct Deviation {
  double state = 0;  // max |x̂ − x̂_ref| (V)
  double cov = 0;    // max relative error of P
  double gain = 0;   // max |K − K_ref|
};

/// Runs `filter` and the Eigen reference on the same jobs; returns the worst deviation.
template <typename Filter>
Deviation run_against_reference(Filter& filter, Variant variant, bool exact, int jobs, std::uint64_t seed) {
  const auto plant = design::reference_plant();
  const auto d = design::synthesize(plant);
  test::ReferenceKalman ref(test::to_eigen(plant.a), test::to_eigen(plant.b), test::to_eigen(plant.c),
                            test::to_eigen(d.qc), test::to_eigen(d.r), test::to_eigen(d.q_constant), plant.period_us,
                            exact);
  ref.reset(test::VecX::Zero(2), test::to_eigen(d.p0), test::VecX::Zero(1));
  TruePlant truth(plant, d, seed);
  std::mt19937_64 rng(seed + 1);
  std::uniform_int_distribution<std::int32_t> tau_dist(0, plant.period_us);
  std::uniform_real_distribution<double> dither(-0.05, 0.05);
  const test::MatX l = test::to_eigen(d.l);
  test::VecX u = test::VecX::Zero(1);
  Deviation dev;
  using S = std::remove_cv_t<std::remove_reference_t<decltype(filter.prediction()[0])>>;
  for (int k = 0; k < jobs; ++k) {
    const std::int32_t tau = tau_dist(rng);
    truth.advance(plant.period_us - tau, u);  // actuation t_{k−1} → sample
    const test::VecX y = truth.measure();
    truth.advance(tau, u);                    // sample → actuation t_k
    if (variant == Variant::kHalf) ref.half(tau, y); else ref.complete(tau, y);
    Vector<S, 1> y_ours;
    y_ours[0] = static_cast<S>(y[0]);
    EXPECT_TRUE(is_exact(filter.update(tau, y_ours)));
    dev.state = std::max(dev.state, (test::to_eigen(filter.prediction()) - ref.prediction()).cwiseAbs().maxCoeff());
    dev.cov = std::max(dev.cov, test::relative_error(test::to_eigen(filter.covariance()), ref.covariance()));
    dev.gain = std::max(dev.gain, (test::to_eigen(filter.gain()) - ref.gain()).cwiseAbs().maxCoeff());
    // Closed loop on the reference estimate (keeps the double integrator bounded) plus dither.
    u = -l * ref.prediction() + test::VecX::Constant(1, dither(rng));
    Vector<S, 1> u_ours;
    u_ours[0] = static_cast<S>(u[0]);
    u[0] = static_cast<double>(u_ours[0]);  // both see the same applied value
    ref.set_applied_input(u);
    filter.set_applied_input(u_ours);
  }
  return dev;
}

template <typename S, template <typename, typename, typename, CovarianceUpdate> class FilterT, typename Disc>
Deviation run_variant(const Disc& disc, Variant variant, NoiseModel noise, int jobs) {
  using K = PlantConstants<S>;
  FilterT<typename K::Format, PlantStructure, Disc, CovarianceUpdate::kSymmetric> filter(K::kDesign, disc, noise);
  return run_against_reference(filter, variant, noise == NoiseModel::kExact, jobs, 42);
}

using test::FilterCase;

class FilterVsEigen : public ::testing::TestWithParam<FilterCase> {};

/// Case `c` in scalar S (double or float) against the Eigen reference over 3000 jobs; the
/// measured deviation is printed for the test report.
template <typename S>
Deviation run_case(const FilterCase& c, const char* scalar) {
  using K = PlantConstants<S>;
  const TableDiscretizer<typename K::Format, PlantStructure, S> table(K::kTable);
  const GenericDiscretizer<typename K::Format, 2, 1> generic(K::kModel);
  Deviation d;
  if (c.variant == Variant::kHalf) {
    d = c.table ? run_variant<S, HalfKalman>(table, c.variant, c.noise, 3000)
                : run_variant<S, HalfKalman>(generic, c.variant, c.noise, 3000);
  } else {
    d = c.table ? run_variant<S, CompleteKalman>(table, c.variant, c.noise, 3000)
                : run_variant<S, CompleteKalman>(generic, c.variant, c.noise, 3000);
  }
  std::cout << "[ measured ] " << scalar << " " << c.name << ": max |dx| " << d.state << " V, P rel " << d.cov
            << ", |dK| " << d.gain << "\n";
  return d;
}

TEST_P(FilterVsEigen, DoubleAgreesToRounding) {
  const Deviation d = run_case<double>(GetParam(), "double");
  // Measured over the six cases: |dx| 1.8e-16 … 2.4e-16 V, P rel 6.2e-16 … 6.4e-16,
  // |dK| 1.7e-16 … 2.2e-16 (a few ulps): bounds ~10× that.
  EXPECT_LT(d.state, 2e-15);
  EXPECT_LT(d.cov, 6e-15);
  EXPECT_LT(d.gain, 2e-15);
}

TEST_P(FilterVsEigen, FloatStaysWithinStatedBounds) {
  const Deviation d = run_case<float>(GetParam(), "float");
  // One 12-bit ADC LSB over ±1.65 V is 0.8 mV: float stays four orders below it. Measured over
  // the six cases: |dx| 4.8e-8 … 6.7e-8 V, P rel 2.2e-7 … 3.1e-7, |dK| 7.0e-8 … 9.1e-8.
  EXPECT_LT(d.state, 4e-7);
  EXPECT_LT(d.cov, 2e-6);
  EXPECT_LT(d.gain, 5e-7);
}

INSTANTIATE_TEST_SUITE_P(
    Variants, FilterVsEigen,
    ::testing::Values(FilterCase{"half_table_exact", Variant::kHalf, NoiseModel::kExact, true},
                      FilterCase{"half_generic_exact", Variant::kHalf, NoiseModel::kExact, false},
                      FilterCase{"half_table_constant", Variant::kHalf, NoiseModel::kConstant, true},
                      FilterCase{"complete_table_exact", Variant::kComplete, NoiseModel::kExact, true},
                      FilterCase{"complete_generic_exact", Variant::kComplete, NoiseModel::kExact, false},
                      FilterCase{"complete_table_constant", Variant::kComplete, NoiseModel::kConstant, true}),
    test::filter_case_name);

/// Random jobs for filters compared side by side (one stream per test, seeded): τ uniform
/// in [tau_min, tau_max] µs, samples and applied inputs N(0, 0.1²), drawn in call order.
class RandomJobs {
 public:
  RandomJobs(std::uint64_t seed, std::int32_t tau_min, std::int32_t tau_max) : rng_(seed), tau_(tau_min, tau_max) {}
  std::int32_t tau() { return tau_(rng_); }
  Vector<double, 1> value() {
    Vector<double, 1> v;
    v[0] = y_(rng_);
    return v;
  }

 private:
  std::mt19937_64 rng_;
  std::uniform_int_distribution<std::int32_t> tau_;
  std::normal_distribution<double> y_{0.0, 0.1};
};

TEST(KalmanFilters, HalfAndCompleteAreTheSameEstimator) {
  // Algebraically identical (brief §5): only the rounding differs.
  using K = PlantConstants<double>;
  const TableDiscretizer<K::Format, PlantStructure, double> table(K::kTable);
  for (NoiseModel noise : {NoiseModel::kExact, NoiseModel::kConstant}) {
    HalfKalman<K::Format, PlantStructure, decltype(table)> half(K::kDesign, table, noise);
    CompleteKalman<K::Format, PlantStructure, decltype(table)> complete(K::kDesign, table, noise);
    RandomJobs jobs(7, 0, 50000);
    for (int k = 0; k < 2000; ++k) {
      const std::int32_t t = jobs.tau();
      const Vector<double, 1> yk = jobs.value();
      ASSERT_TRUE(is_exact(half.update(t, yk)));
      ASSERT_TRUE(is_exact(complete.update(t, yk)));
      EXPECT_LT(std::fabs(half.prediction()[0] - complete.prediction()[0]), 1e-12);
      EXPECT_LT(std::fabs(half.prediction()[1] - complete.prediction()[1]), 1e-12);
      EXPECT_LT(std::fabs(half.gain()[0] - complete.gain()[0]), 1e-12);
      const Vector<double, 1> u = jobs.value();
      half.set_applied_input(u);
      complete.set_applied_input(u);
    }
  }
}

/// Filters over the nearest-grid-point table fed raw τ ∈ [tau_min, tau_max] against filters
/// over the exact table fed τ rounded to the nearest grid point (half away from zero): the
/// statuses agree and the estimates are the same bits, job by job.
void expect_nearest_equals_exact_on_rounded_tau(std::uint64_t seed, std::int32_t tau_min, std::int32_t tau_max,
                                                int jobs) {
  // GIVEN filters over the nearest-grid-point table and over the exact table
  using K = PlantConstants<double>;
  using Exact = TableDiscretizer<K::Format, PlantStructure, double>;
  using Nearest = TableDiscretizer<K::Format, PlantStructure, double, OutOfRange::kExtend, SubGrid::kNearest>;
  const Exact exact(K::kTable);
  const Nearest nearest(K::kTable);
  const std::int32_t g = K::kTable.granularity_us;
  HalfKalman<K::Format, PlantStructure, Nearest> half_n(K::kDesign, nearest, NoiseModel::kExact);
  HalfKalman<K::Format, PlantStructure, Exact> half_e(K::kDesign, exact, NoiseModel::kExact);
  CompleteKalman<K::Format, PlantStructure, Nearest> comp_n(K::kDesign, nearest, NoiseModel::kExact);
  CompleteKalman<K::Format, PlantStructure, Exact> comp_e(K::kDesign, exact, NoiseModel::kExact);
  RandomJobs random(seed, tau_min, tau_max);
  for (int k = 0; k < jobs; ++k) {
    // WHEN the nearest filters get raw τ and the exact ones τ rounded to the grid
    const std::int32_t t = random.tau();
    const std::int32_t rounded = t >= 0 ? ((t + g / 2) / g) * g : -(((-t) + g / 2) / g) * g;
    const Vector<double, 1> yk = random.value();
    // THEN no invariant fires, the statuses agree and the estimates are the same bits
    ASSERT_EQ(half_n.update(t, yk), half_e.update(rounded, yk)) << "job " << k;
    ASSERT_EQ(comp_n.update(t, yk), comp_e.update(rounded, yk)) << "job " << k;
    for (std::size_t i = 0; i < 2; ++i) {
      ASSERT_EQ(half_n.prediction()[i], half_e.prediction()[i]) << "job " << k;
      ASSERT_EQ(comp_n.prediction()[i], comp_e.prediction()[i]) << "job " << k;
    }
    const Vector<double, 1> u = random.value();
    half_n.set_applied_input(u);
    half_e.set_applied_input(u);
    comp_n.set_applied_input(u);
    comp_e.set_applied_input(u);
  }
}

TEST(KalmanFilters, NearestPolicyFilterEqualsTheExactFilterOnRoundedTau) {
  using K = PlantConstants<double>;
  expect_nearest_equals_exact_on_rounded_tau(11, 0, K::kDesign.period_us, 2000);
}

TEST(KalmanFilters, NearestPolicyRoundsNegativeOffGridTauLikeTheExactFilterOnRoundedTau) {
  // τ < 0 (sample after the actuation: a scheduling fault), off the grid
  const std::int32_t g = PlantConstants<double>::kTable.granularity_us;
  expect_nearest_equals_exact_on_rounded_tau(12, -5 * g - g / 2, -1, 500);
}

TEST(KalmanFilters, JosephAndSymmetricFormsAgree) {
  using K = PlantConstants<double>;
  const TableDiscretizer<K::Format, PlantStructure, double> table(K::kTable);
  HalfKalman<K::Format, PlantStructure, decltype(table), CovarianceUpdate::kSymmetric> sym(K::kDesign, table,
                                                                                          NoiseModel::kExact);
  HalfKalman<K::Format, PlantStructure, decltype(table), CovarianceUpdate::kJoseph> jos(K::kDesign, table,
                                                                                       NoiseModel::kExact);
  RandomJobs jobs(8, 0, 50000);
  for (int k = 0; k < 1000; ++k) {
    const std::int32_t t = jobs.tau();
    const Vector<double, 1> yk = jobs.value();
    ASSERT_EQ(sym.update(t, yk), jos.update(t, yk));
    EXPECT_LT(test::relative_error(test::to_eigen(sym.covariance()), test::to_eigen(jos.covariance())), 1e-12);
  }
}

TEST(KalmanFilters, StandardFilterConvergesToTheDesignGain) {
  using K = PlantConstants<double>;
  const auto d = design::synthesize(design::reference_plant());
  StandardKalman<K::Format, PlantStructure> filter(K::kDesign, NoiseModel::kExact);
  Vector<double, 1> y;
  for (int k = 0; k < 400; ++k) ASSERT_EQ(filter.update(0, y), Status::kOk);
  EXPECT_NEAR(filter.gain()[0], d.kalman_gain(0, 0), 1e-10);
  EXPECT_NEAR(filter.gain()[1], d.kalman_gain(1, 0), 1e-10);
}

TEST(KalmanFilters, SingularInnovationIsReportedAndLeavesTheStateAlone) {
  using K = PlantConstants<double>;
  auto design = K::kDesign;
  design.r(0, 0) = 0.0;
  design.p0 = Matrix<double, 2, 2>{};
  StandardKalman<K::Format, PlantStructure> filter(design, NoiseModel::kExact);
  Vector<double, 1> y;
  y[0] = 1.0;
  EXPECT_EQ(filter.update(0, y), Status::kSingular);
  EXPECT_EQ(filter.prediction()[0], 0.0);
}

TEST(DeadbeatObserver, ReconstructsTheStateAfterNNoiseFreeSamples) {
  using K = PlantConstants<double>;
  const auto plant = design::reference_plant();
  const test::MatX phi = test::to_eigen(K::kDesign.phi_h);
  const test::MatX gamma = test::to_eigen(K::kDesign.gamma_h);
  DeadbeatObserver<K::Format, PlantStructure> obs(K::kDesign);
  test::VecX x(2);
  x << 0.3, -0.1;
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<double> ud(-0.5, 0.5);
  for (int k = 0; k < 10; ++k) {
    Vector<double, 1> y;
    y[0] = x[0];
    ASSERT_EQ(obs.update(0, y), Status::kOk);
    if (k >= 1) {  // n = 2 samples
      EXPECT_NEAR(obs.prediction()[0], x[0], 1e-12);
      EXPECT_NEAR(obs.prediction()[1], x[1], 1e-12);
    }
    test::VecX u(1);
    u[0] = ud(rng);
    Vector<double, 1> uo;
    uo[0] = u[0];
    obs.set_applied_input(uo);
    x = phi * x + gamma * u;
  }
}

}  // namespace
}  // namespace oneshot
