/// @file numre_test.cpp
/// @brief NUMRE (numre-petc.md §4) against Eigen: one N-period update equals the closed
///        form with A^N and W_e(N) (and the printed frozen-noise form), and with N ≡ 1 and
///        zero thresholds the closed loop's NUMRE is the standard Kalman filter.
#include <gtest/gtest.h>

#include <string>

#include <Eigen/Dense>
#include <random>

#include "oneshot/node/numre_estimator.hpp"
#include "petc_sim.hpp"
#include "support/measured_text.hpp"

namespace {

using oneshot::test::sci;

using namespace oneshot::sim::petc;
using Mat = Eigen::MatrixXd;
using Vec = Eigen::VectorXd;

using Ix = Eigen::Index;
Ix ix(std::size_t i) { return static_cast<Ix>(i); }

Mat eig(const DenseMatrix& d) {
  Mat m(ix(d.rows), ix(d.cols));
  for (std::size_t i = 0; i < d.rows; ++i)
    for (std::size_t j = 0; j < d.cols; ++j) m(ix(i), ix(j)) = d(i, j);
  return m;
}

template <std::size_t N>
oneshot::node::NumreModel<double, N> node_model(const EstimatorModel& e) {
  oneshot::node::NumreModel<double, N> m;
  for (std::size_t i = 0; i < N; ++i) {
    for (std::size_t j = 0; j < N; ++j) m.a(i, j) = e.a(i, j);
    m.b[i] = e.b(i, 0);
    m.b_w[i] = e.b_w(i, 0);
    m.c[i] = e.c(0, i);
    m.c_bar[i] = e.c_bar(0, i);
  }
  m.w = e.w;
  m.v = e.v;
  return m;
}

double rel_err(const Mat& a, const Mat& ref) { return (a - ref).cwiseAbs().maxCoeff() / ref.cwiseAbs().maxCoeff(); }

struct Joseph {
  Vec x;
  Mat p;
};

Joseph joseph(const Vec& x, const Mat& m, const Mat& c, double v, double y) {
  const double s = (c * m * c.transpose())(0, 0) + v;
  const Vec k = m * c.transpose() / s;
  const Mat ikc = Mat::Identity(x.size(), x.size()) - k * c;
  return {x + k * (y - (c * x)(0, 0)), ikc * m * ikc.transpose() + k * v * k.transpose()};
}

class NumreTest : public ::testing::TestWithParam<bool> {};

// One update after N = 37 silent periods equals x̂ = A^N x̂ + Σ A^{N−1−c} B u_c,
// M = A^N P (A^N)ᵀ + W_e(N) and the Joseph correction, computed in Eigen.
TEST_P(NumreTest, NStepUpdateEqualsClosedForm) {
  const bool frozen = GetParam();
  const PlantFacts plant = load_plant_facts(default_plant_path());
  const EstimatorModel& e = plant.augmented;
  constexpr std::size_t n = 12;
  const Mat a = eig(e.a), b = eig(e.b), bw = eig(e.b_w), c = eig(e.c);
  std::mt19937_64 rng(7);
  std::normal_distribution<double> g(0.0, 1.0);
  Vec x0(ix(n));
  for (std::size_t i = 0; i < n; ++i) x0(ix(i)) = 0.1 * g(rng);
  Mat l(ix(n), ix(n));
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = 0; j < n; ++j) l(ix(i), ix(j)) = 1e-3 * g(rng);
  const Mat p0 = l * l.transpose();
  constexpr std::size_t kN = 37;
  std::vector<double> u(kN);
  for (double& v : u) v = 0.2 * g(rng);
  const double y = 0.3;

  oneshot::node::NumreEstimator<double, n> est(node_model<n>(e), frozen ? oneshot::node::NoiseAccumulation::kFrozen
                                                                       : oneshot::node::NoiseAccumulation::kSum);
  oneshot::Vector<double, n> xs;
  oneshot::Matrix<double, n, n> ps;
  for (std::size_t i = 0; i < n; ++i) {
    xs[i] = x0(ix(i));
    for (std::size_t j = 0; j < n; ++j) ps(i, j) = p0(ix(i), ix(j));
  }
  est.reset(xs, ps);
  for (double v : u) est.predict(v);
  ASSERT_EQ(est.correct(y), oneshot::Status::kOk);
  EXPECT_EQ(est.last_multiplicity(), kN);

  Mat an = Mat::Identity(ix(n), ix(n));
  Vec xp = Vec::Zero(ix(n));
  Mat we = Mat::Zero(ix(n), ix(n));
  Mat gsum = Mat::Zero(ix(n), 1);
  for (std::size_t cidx = 0; cidx < kN; ++cidx) {
    we += an * bw * e.w * bw.transpose() * an.transpose();  // A^c B_w W B_wᵀ (A^c)ᵀ
    gsum += an * bw;
    an = a * an;
  }
  for (std::size_t cidx = 0; cidx < kN; ++cidx) {
    Mat apow = Mat::Identity(ix(n), ix(n));
    for (std::size_t q = 0; q + 1 + cidx < kN; ++q) apow = a * apow;  // A^{N−1−c}
    xp += apow * b * u[cidx];
  }
  xp += an * x0;
  const Mat m = an * p0 * an.transpose() + (frozen ? Mat(gsum * e.w * gsum.transpose()) : we);
  const Joseph ref = joseph(xp, m, c, e.v, y);
  Mat xn(ix(n), 1), pn(ix(n), ix(n));
  for (std::size_t i = 0; i < n; ++i) {
    xn(ix(i), 0) = est.state()[i];
    for (std::size_t j = 0; j < n; ++j) pn(ix(i), ix(j)) = est.covariance()(i, j);
  }
  const double ex = rel_err(xn, ref.x), ep = rel_err(pn, ref.p);
  RecordProperty("x_rel_err", sci(ex));
  RecordProperty("p_rel_err", sci(ep));
  EXPECT_LT(ex, 1e-12);  // measured 1.6e-13 (sum), 2.1e-13 (frozen)
  EXPECT_LT(ep, 1e-10);  // measured 5.7e-12, 1.0e-11
}

INSTANTIATE_TEST_SUITE_P(Accumulation, NumreTest, ::testing::Values(false, true));

// With zero thresholds and noise every sample and every packet is sent (N ≡ 1): the NUMRE
// inside the closed loop is the standard Kalman filter on the same y and applied u.
TEST(NumreClosedLoop, MultiplicityOneEqualsStandardKalman) {
  PetcOptions o;
  o.steps = 120;
  const PetcSetup s = make_setup(o);
  CaseSpec c = default_cases()[3];
  c.sigma_s = c.delta_s = c.sigma_c = c.delta_c = 0.0;
  RunTrace t;
  const std::vector<double> v = run_case(s, c, 5, &t);
  ASSERT_EQ(t.x_hat.size(), o.steps);
  EXPECT_EQ(v[5], static_cast<double>(o.steps));  // every sample sent
  for (std::size_t k = 1; k < t.multiplicity.size(); ++k) ASSERT_EQ(t.multiplicity[k], 1U) << k;
  // The node runs in the block-diagonal basis z = T⁻¹x (petc_modal.hpp): x̂ = T ẑ against
  // the standard Kalman filter on the augmented model.
  const EstimatorModel& e = s.plant.augmented;
  const Mat tm = eig(s.node_model.t);
  const Mat a = eig(e.a), b = eig(e.b), bw = eig(e.b_w), cm = eig(e.c);
  const Mat q = bw * e.w * bw.transpose();
  Vec x = Vec::Zero(12);
  Mat p = Mat::Zero(12, 12);
  double worst = 0;
  for (std::size_t k = 0; k < o.steps; ++k) {
    if (k > 0) {
      x = a * x + b * t.u[k - 1];
      p = a * p * a.transpose() + q;
    }
    const Joseph j = joseph(x, p, cm, e.v, t.y_meas[k]);
    x = j.x;
    p = j.p;
    Vec z(12);
    for (std::size_t i = 0; i < 12; ++i) z(ix(i)) = t.x_hat[k][i];
    const Vec got = tm * z;
    worst = std::max(worst, (got - x).cwiseAbs().maxCoeff() / std::max(1e-300, x.cwiseAbs().maxCoeff()));
  }
  RecordProperty("worst_rel_err", sci(worst));
  EXPECT_LT(worst, 5e-13);  // measured 1.2e-13 (node in the block-diagonal basis, mapped back)
}

}  // namespace
