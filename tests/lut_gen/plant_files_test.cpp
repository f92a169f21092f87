/// @file plant_files_test.cpp
/// @brief Every shipped plant file loads and designs; the reference design keeps its
///        numbers; equivalent plant forms give equivalent designs; designs of n = 3, 6, 12
///        against Eigen (DARE residuals in long double, spectral radii by EigenSolver: support/eigen_reference).
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>

#include "oneshot/design/controller_synthesis.hpp"
#include "oneshot/design/dense_ops.hpp"
#include "support/eigen_reference.hpp"
#include "support/shipped_plants.hpp"
#include "support/test_plants.hpp"

namespace oneshot::design {
namespace {

using test::MatX;

std::string plant_path(const std::string& file) { return std::string(ONESHOT_PLANTS_DIR) + "/" + file; }

/// Relative residuals (long double) of the design's LQR and Kalman Riccati solutions.
void check_riccati_residuals(const PlantDescription& p, const DesignResult& d, double tol) {
  const MatX phi = test::to_eigen(d.phi_h);
  if (d.lqr_available && d.exogenous_states == 0) {
    EXPECT_LT(test::dare_residual_long(phi, test::to_eigen(d.gamma_h), test::to_eigen(d.q1), test::to_eigen(d.q2),
                                       test::to_eigen(d.q12), test::to_eigen(d.riccati)),
              tol)
        << p.name;
  }
  // The prior Riccati equation: A = Φᵀ, B = Cᵀ, no cross weight.
  const MatX ct = test::to_eigen(p.c).transpose();
  EXPECT_LT(test::dare_residual_long(phi.transpose(), ct, test::to_eigen(d.qd_h), test::to_eigen(d.r),
                                     MatX::Zero(ct.rows(), ct.cols()), test::to_eigen(d.kalman_prior)),
            tol)
      << p.name;
}

void check_radii(const PlantDescription& p, const DesignResult& d) {
  const MatX phi = test::to_eigen(d.phi_h);
  const MatX k = test::to_eigen(d.kalman_gain);
  const MatX c = test::to_eigen(p.c);
  const MatX est = (MatX::Identity(phi.rows(), phi.cols()) - k * c) * phi;
  EXPECT_NEAR(d.estimator_radius, test::spectral_radius(est), 1e-13) << p.name;  // measured ≤ 1.2e−15
  EXPECT_LT(d.estimator_radius, 1.0) << p.name;
  if (d.lqr_available) {
    const Eigen::Index np = phi.rows() - static_cast<Eigen::Index>(d.exogenous_states);
    const MatX cl = phi.topLeftCorner(np, np) - test::to_eigen(d.gamma_h).topRows(np) * test::to_eigen(d.l).leftCols(np);
    EXPECT_NEAR(d.closed_loop_radius, test::spectral_radius(cl), 1e-13) << p.name;
    EXPECT_LT(d.closed_loop_radius, 1.0) << p.name;
  }
}

class PlantFile : public ::testing::TestWithParam<const char*> {};

TEST_P(PlantFile, LoadsAndDesigns) {
  const PlantDescription p = load_plant_file(plant_path(GetParam()));
  const DesignResult d = synthesize(p);
  EXPECT_EQ(d.phi_h.rows, p.n());
  check_radii(p, d);
  check_riccati_residuals(p, d, 1e-14);  // measured ≤ 9.3e−16
}

INSTANTIATE_TEST_SUITE_P(Shipped, PlantFile,
                         ::testing::ValuesIn(test::kShippedPlantFiles),
                         [](const ::testing::TestParamInfo<const char*>& i) { return test::plant_file_stem(i.param); });

TEST(PlantFiles, ReferenceBoardKeepsItsDesign) {
  const DesignResult d = synthesize(load_plant_file(plant_path("reference_board.json")));
  EXPECT_NEAR(d.l(0, 0), 0.39527, 5e-6);
  EXPECT_NEAR(d.l(0, 1), -0.97302, 5e-6);
  EXPECT_NEAR(d.kalman_gain(0, 0), 0.29429, 5e-6);
  EXPECT_NEAR(d.kalman_gain(1, 0), -0.04200, 5e-6);
  EXPECT_TRUE(d.deadbeat);
  EXPECT_EQ(load_plant_file(plant_path("reference_board.json")).a, reference_plant().a);
}

TEST(PlantFiles, NetworkedBoardTracksV1Only) {
  const PlantDescription p = load_plant_file(plant_path("networked_board.json"));
  const DesignResult d = synthesize(p);
  ASSERT_TRUE(d.tracking) << d.tracking_unavailable_reason;
  // x_ref = [r, 0]ᵀ, u_eq = 0; the v2 set-point does not enter.
  EXPECT_EQ(d.nx, (DenseMatrix{2, 2, {1.0, 0.0, 0.0, 0.0}}));
  EXPECT_EQ(d.nu, (DenseMatrix{1, 2, {0.0, 0.0}}));
  EXPECT_FALSE(d.deadbeat);
  // Same LQR as the reference board (same A, B, cost).
  EXPECT_EQ(d.l, synthesize(reference_plant()).l);
}

TEST(PlantFiles, HddCancelsTheEstimatedDisturbanceAtTheInput) {
  const PlantDescription p = load_plant_file(plant_path("hdd_numre.json"));
  const DesignResult d = synthesize(p);
  ASSERT_TRUE(d.lqr_available);
  EXPECT_EQ(d.exogenous_states, 2U);
  EXPECT_EQ(block(d.l, 0, 10, 1, 2), block(p.c_bar, 0, 10, 1, 2));  // L_d = C_d
  EXPECT_NEAR(d.exogenous_radius, 1.0, 1e-12);                      // the undamped 60 Hz oscillator
  ASSERT_TRUE(d.tracking);
  EXPECT_NEAR(1.0 / d.nu(0, 0), 7.0, 0.05);  // u_eq = r / DC gain
  EXPECT_FALSE(d.deadbeat);                  // N₂ = 1 leaves two unobservable states
  EXPECT_EQ(d.gamma_w_h, p.b_w);
}

TEST(PlantFiles, IntensityAndPerPeriodCovarianceAreEquivalent) {
  // Q_c = Qn / h: the reference with process_intensity = 2e−7/0.05 designs the same.
  const std::string text = test::reference_with("/noise/process_covariance_per_period", "");
  nlohmann::json j = nlohmann::json::parse(text);
  j["noise"]["process_intensity"] = {{4e-6, 0.0}, {0.0, 4e-6}};
  const DesignResult a = synthesize(reference_plant());
  const DesignResult b = synthesize(parse_plant(j.dump(), "intensity"));
  EXPECT_LT(test::relative_error(test::to_eigen(b.qd_h), test::to_eigen(a.qd_h)), 1e-15);
  EXPECT_LT(test::relative_error(test::to_eigen(b.q_constant), test::to_eigen(a.q_constant)), 1e-15);
  EXPECT_LT(test::relative_error(test::to_eigen(b.kalman_gain), test::to_eigen(a.kalman_gain)), 1e-14);
}

TEST(PlantFiles, DiscreteFormOfTheReferenceDesignsTheSame) {
  // Φ(h), Γ(h), Q_d(h) of the reference entered as a discrete plant, against the continuous
  // reference with the same discrete weights (DLQR(Φ, Γ, I, 1)).
  const DesignResult ref = synthesize(reference_plant());
  nlohmann::json cont = nlohmann::json::parse(reference_plant_json());
  cont["cost"] = {{"Q1", {{1.0, 0.0}, {0.0, 1.0}}}, {"Q2", {{1.0}}}};
  nlohmann::json disc = cont;
  for (const char* k : {"A", "B", "table", "board"}) disc.erase(k);
  disc["form"] = "discrete";
  disc["Phi"] = {{ref.phi_h(0, 0), ref.phi_h(0, 1)}, {ref.phi_h(1, 0), ref.phi_h(1, 1)}};
  disc["Gamma"] = {{ref.gamma_h(0, 0)}, {ref.gamma_h(1, 0)}};
  disc["noise"]["process_covariance_per_period"] = {{ref.qd_h(0, 0), ref.qd_h(0, 1)}, {ref.qd_h(1, 0), ref.qd_h(1, 1)}};
  const DesignResult c = synthesize(parse_plant(cont.dump(), "continuous"));
  const DesignResult d = synthesize(parse_plant(disc.dump(), "discrete"));
  EXPECT_LT(test::relative_error(test::to_eigen(d.l), test::to_eigen(c.l)), 1e-14);
  EXPECT_LT(test::relative_error(test::to_eigen(d.kalman_gain), test::to_eigen(c.kalman_gain)), 1e-14);
  EXPECT_LT(test::relative_error(test::to_eigen(d.nx), test::to_eigen(c.nx)), 1e-14);
  EXPECT_TRUE(d.deadbeat);
}

/// A discrete plant JSON with random Φ (one unstable mode), Γ, C (n, m, p), Q = I, R = I.
std::string random_discrete_plant(std::size_t n, std::size_t m, std::size_t p, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> nd(0.0, 1.0);
  const auto mat = [&](std::size_t r, std::size_t c, double scale) {
    nlohmann::json rows = nlohmann::json::array();
    for (std::size_t i = 0; i < r; ++i) {
      nlohmann::json row = nlohmann::json::array();
      for (std::size_t k = 0; k < c; ++k) row.push_back(scale * nd(rng));
      rows.push_back(row);
    }
    return rows;
  };
  const auto eye = [](std::size_t k) {
    nlohmann::json rows = nlohmann::json::array();
    for (std::size_t i = 0; i < k; ++i) {
      nlohmann::json row = nlohmann::json::array();
      for (std::size_t c = 0; c < k; ++c) row.push_back(i == c ? 1.0 : 0.0);
      rows.push_back(row);
    }
    return rows;
  };
  nlohmann::json j;
  j["form"] = "discrete";
  j["Phi"] = mat(n, n, 1.1 / std::sqrt(static_cast<double>(n)));
  j["Gamma"] = mat(n, m, 1.0);
  j["C"] = mat(p, n, 1.0);
  j["period_us"] = 1000;
  j["cost"] = {{"Q1", eye(n)}, {"Q2", eye(m)}};
  j["noise"] = {{"process_covariance_per_period", eye(n)}, {"measurement_covariance", eye(p)}};
  return j.dump();
}

class DesignAgainstEigen : public ::testing::TestWithParam<std::size_t> {};

TEST_P(DesignAgainstEigen, ResidualsAndRadii) {
  const std::size_t n = GetParam();
  for (std::uint64_t seed = 1; seed <= 3; ++seed) {
    const PlantDescription p = parse_plant(random_discrete_plant(n, 2, 2, 1000 * n + seed), "random");
    const DesignResult d = synthesize(p);
    check_radii(p, d);
    check_riccati_residuals(p, d, 1e-14);  // measured ≤ 9.3e−16 up to n = 12
  }
}

INSTANTIATE_TEST_SUITE_P(Sizes, DesignAgainstEigen, ::testing::Values(3U, 6U, 12U));

}  // namespace
}  // namespace oneshot::design
