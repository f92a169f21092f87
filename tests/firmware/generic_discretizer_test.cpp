/// @file generic_discretizer_test.cpp
/// @brief The generic Φ/Γ/Q_d routine against Eigen (expm, Van Loan) and quadrature,
///        for the nilpotent reference and for non-nilpotent plants, in double and float.
#include <gtest/gtest.h>

#include <algorithm>
#include <iostream>

#include "oneshot/design/controller_synthesis.hpp"
#include "oneshot/design/fixed_size.hpp"
#include "oneshot/generic_discretizer.hpp"
#include "support/eigen_reference.hpp"
#include "support/test_plants.hpp"

namespace oneshot {
namespace {

struct Errors {
  double phi = 0, gamma = 0, qd = 0, qd_quadrature = 0;
};

template <typename S, std::size_t N, std::size_t M>
Errors generic_errors(const design::PlantDescription& plant) {
  const design::DesignResult d = design::synthesize(plant);
  const GenericDiscretizer<UniformFormat<S>, N, M> gen(design::continuous_model_per_us<S, N, M>(plant, d));
  const test::MatX a = test::to_eigen(plant.a);
  const test::MatX b = test::to_eigen(plant.b);
  const test::MatX qc = test::to_eigen(d.qc);
  Errors e;
  // Over the table range and beyond (the complete filter's argument reaches 2h).
  for (std::int32_t tau = 0; tau <= 2 * plant.period_us; tau += 733) {
    Discretization<UniformFormat<S>, N, M> ours;
    EXPECT_EQ(gen.discretize(tau, ours, WithQd::kYes), Status::kOk);
    const test::Triple ref = test::reference_triple(a, b, qc, tau * 1e-6);
    e.phi = std::max(e.phi, test::relative_error(test::to_eigen(ours.phi), ref.phi));
    e.gamma = std::max(e.gamma, test::relative_error(test::to_eigen(ours.gamma), ref.gamma));
    if (tau > 0) e.qd = std::max(e.qd, test::relative_error(test::to_eigen(ours.qd), ref.qd));
    if (tau > 0 && tau % (733 * 13) == 0) {
      e.qd_quadrature = std::max(e.qd_quadrature, test::relative_error(test::to_eigen(ours.qd),
                                                                         test::qd_by_quadrature(a, qc, tau * 1e-6)));
    }
  }
  return e;
}

template <typename S, std::size_t N, std::size_t M>
void expect_close(const design::PlantDescription& plant, double tol) {
  const Errors e = generic_errors<S, N, M>(plant);
  std::cout << "[ measured ] generic " << (sizeof(S) == 4 ? "float " : "double") << " " << plant.name
            << ": max rel err Phi " << e.phi << ", Gamma " << e.gamma << ", Qd " << e.qd << " (quadrature "
            << e.qd_quadrature << ")\n";
  EXPECT_LT(e.phi, tol);
  EXPECT_LT(e.gamma, tol);
  EXPECT_LT(e.qd, tol);
  EXPECT_LT(e.qd_quadrature, std::max(tol, 1e-9));  // quadrature itself is accurate to ~1e-10
}

TEST(GenericDiscretizer, ReferenceDouble) { expect_close<double, 2, 1>(design::reference_plant(), 1e-13); }
TEST(GenericDiscretizer, ReferenceFloat) { expect_close<float, 2, 1>(design::reference_plant(), 2e-6); }
TEST(GenericDiscretizer, DampedOscillatorDouble) { expect_close<double, 2, 1>(test::damped_oscillator(), 1e-12); }
TEST(GenericDiscretizer, DampedOscillatorFloat) { expect_close<float, 2, 1>(test::damped_oscillator(), 2e-5); }
TEST(GenericDiscretizer, UnstablePoleDouble) { expect_close<double, 2, 1>(test::unstable_plant(), 1e-12); }
TEST(GenericDiscretizer, UnstablePoleFloat) { expect_close<float, 2, 1>(test::unstable_plant(), 2e-5); }
TEST(GenericDiscretizer, ThreeStateDouble) { expect_close<double, 3, 1>(test::three_state_plant(), 1e-12); }
TEST(GenericDiscretizer, ThreeStateFloat) { expect_close<float, 3, 1>(test::three_state_plant(), 2e-5); }

TEST(GenericDiscretizer, NegativeTimeIsClampedToZero) {
  const auto plant = design::reference_plant();
  const auto d = design::synthesize(plant);
  const GenericDiscretizer<UniformFormat<double>, 2, 1> gen(design::continuous_model_per_us<double, 2, 1>(plant, d));
  Discretization<UniformFormat<double>, 2, 1> out;
  EXPECT_EQ(gen.discretize(-5, out, WithQd::kYes), Status::kClamped);
  EXPECT_EQ(out.phi(0, 1), 0.0);
  EXPECT_EQ(out.gamma(0, 0), 0.0);
  EXPECT_EQ(out.qd(0, 0), 0.0);
}

}  // namespace
}  // namespace oneshot
