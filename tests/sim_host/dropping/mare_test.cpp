/// @file mare_test.cpp
/// @brief The MARE tool: λ_sys, the fixed point at λ = 1 against the design step's DARE,
///        one MARE step against Eigen, the λc bracket, and the LMI certificate (granted above
///        λc, refused below it for every candidate).
#include <gtest/gtest.h>

#include <cmath>

#include "dropping_plant.hpp"
#include "lambda_c.hpp"
#include "mare.hpp"
#include "study_plant.hpp"
#include "support/eigen_reference.hpp"

namespace oneshot::dropping {
namespace {

using test::MatX;

TEST(Mare, LambdaSysFromTheUnstableMode) {
  // Φ is upper triangular: its eigenvalues are its diagonal.
  double rho = 0;
  for (std::size_t i = 0; i < kN; ++i) rho = std::max(rho, std::fabs(study_plant().phi(i, i)));
  EXPECT_NEAR(study_plant().rho, rho, 1e-12);
  EXPECT_NEAR(study_plant().lambda_sys, 1 - 1 / (rho * rho), 1e-12);
  EXPECT_EQ(lambda_sys_from_radius(0.9), 0.0);
}

TEST(Mare, OneStepMatchesEigen) {
  const MareModel<kN, kP> m = study_plant().mare();
  Matrix<double, kN, kN> p;
  for (std::size_t i = 0; i < kN; ++i)
    for (std::size_t j = 0; j < kN; ++j) p(i, j) = (i == j ? 50.0 : 0.0) + 3.0 * static_cast<double>(i + j);
  const double lambda = 0.6;
  const MatX phi = test::to_eigen(m.phi), c = test::to_eigen(m.c);
  const MatX mm = phi * test::to_eigen(p) * phi.transpose() + test::to_eigen(m.q);
  const MatX s = c * mm * c.transpose() + test::to_eigen(m.r);
  const MatX g = mm - lambda * mm * c.transpose() * s.inverse() * c * mm;
  EXPECT_LE(test::relative_error(test::to_eigen(mare_map(m, p, lambda)), g), 1e-14);
  EXPECT_LE(test::relative_error(test::to_eigen(mare_gain(m, p)), mm * c.transpose() * s.inverse()), 1e-14);
}

TEST(Mare, FixedPointAtOneIsTheKalmanPosterior) {
  Matrix<double, kN, kN> p;
  const MareOutcome o = mare_fixed_point(study_plant().mare(), 1.0, p);
  ASSERT_TRUE(o.converged) << o.reason;
  // The design step solves the DARE by QZ (LAPACK): an independent route.
  EXPECT_LE(test::relative_error(test::to_eigen(p), test::to_eigen(study_plant().design.kalman_posterior)), 1e-9);
}

TEST(Mare, BisectionBracketsLambdaC) {
  const MareModel<kN, kP> m = study_plant().mare();
  const LambdaCBracket b = lambda_c_bisection(m, study_plant().lambda_sys, 1e-4);
  ASSERT_TRUE(b.hi_converges);
  EXPECT_LE(b.hi - b.lo, 1e-4);
  EXPECT_GE(b.lo, study_plant().lambda_sys);
  Matrix<double, kN, kN> p;
  EXPECT_TRUE(mare_fixed_point(m, b.hi, p).converged);
  if (b.lo > study_plant().lambda_sys) {
    EXPECT_FALSE(mare_fixed_point(m, b.lo, p).converged);
  }
  EXPECT_FALSE(mare_fixed_point(m, 0.3, p).converged);  // below λ_sys: diverges
}

TEST(Mare, CertificateGrantedAboveRefusedBelow) {
  const MareModel<kN, kP> m = study_plant().mare();
  for (double l : {1.0, 0.44, 0.364}) {
    const Certificate c = certify(m, l);
    EXPECT_TRUE(c.certified) << "lambda " << l << ": " << c.reason;
    EXPECT_GT(c.min_pivot, 0);
  }
  for (double l : {0.3, 0.2, study_plant().lambda_sys - 1e-3}) {
    const Certificate c = certify(m, l);
    EXPECT_FALSE(c.certified) << "lambda " << l;
  }
  // Below λ_sys no P > 0 has Ω(P, λ, K) < P: every candidate must fail the Cholesky test,
  // including fixed points (and gains) that are certified at higher λ.
  for (double from : {0.37, 0.44, 1.0}) {
    Matrix<double, kN, kN> p;
    ASSERT_TRUE(mare_fixed_point(m, from, p, MareSettings{}, 1e-3).converged);
    EXPECT_TRUE(check_lmi(m, from, p, mare_gain(m, p)).certified) << from;
    for (double below : {0.3, study_plant().lambda_sys - 1e-3}) {
      const Certificate c = check_lmi(m, below, p, mare_gain(m, p));
      EXPECT_FALSE(c.certified) << "candidate from " << from << " at " << below;
      EXPECT_LE(c.min_pivot, 0);
    }
  }
}

TEST(Mare, ToolReportsEveryRequestedLambda) {
  LambdaCOptions o;
  o.mare.max_iterations = 500'000;  // the slowest bisection run here takes ~1e5 steps
  const nlohmann::json j = lambda_c_report(study_plant(), o);
  ASSERT_EQ(j.at("points").size(), o.lambdas.size());
  EXPECT_LE(j.at("lambda_c_bracket_width").get<double>(), 1e-4);
  for (const auto& p : j.at("points")) {
    const bool converged = p.at("converged").get<bool>();
    EXPECT_EQ(p.at("certificate").at("verdict").get<std::string>() == "certified", converged) << p.dump();
  }
}

}  // namespace
}  // namespace oneshot::dropping
