/// @file fuzz_plant.cpp
/// @brief libFuzzer harness of the plant parser: parse_plant(text, source), then the design.
///
/// Oracle: a plant that parse_plant accepts has, when it has one, a board the emulator can
/// run (PWM period of at least 1 ns and at most h, duty steps of at least 1 ns) and a table
/// covering h (issue 11); it either gets a clean DesignError from the design step, or a
/// design whose JSON holds no NaN, Inf or null, with a stable estimator (spectral radius of
/// (I − K C) Φ(h) below 1, computed here with Eigen, independently of the design's own
/// figure), a stable closed loop on the regulated states (Φ − Γ L) when an LQR gain was
/// designed, and, when a deadbeat observer is reported available, a non-zero gain with
/// ((I − K_db C) Φ)ⁿ = 0.
#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>

#include "fuzz_oracle.hpp"
#include "oneshot/design/controller_synthesis.hpp"
#include "oneshot/design/design_report.hpp"
#include "oneshot/design/plant_description.hpp"
#include "oneshot/util/strict_json.hpp"

namespace {

using oneshot::design::DenseMatrix;

Eigen::MatrixXd eigen_of(const DenseMatrix& m) {
  Eigen::MatrixXd e(static_cast<Eigen::Index>(m.rows), static_cast<Eigen::Index>(m.cols));
  for (std::size_t i = 0; i < m.rows; ++i)
    for (std::size_t j = 0; j < m.cols; ++j) e(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j)) = m(i, j);
  return e;
}

double spectral_radius(const Eigen::MatrixXd& m) {
  return m.eigenvalues().cwiseAbs().maxCoeff();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  namespace d = oneshot::design;
  using oneshot::fuzz::require;
  const std::string text(reinterpret_cast<const char*>(data), size);
  d::PlantDescription plant;
  try {
    plant = d::parse_plant(text, "fuzz");
  } catch (const d::PlantError&) {
    return 0;  // refused with a message: fine
  }
  if (plant.has_board) {
    const double pwm_period_ns = 1e9 / plant.board.pwm_frequency_hz;
    require(pwm_period_ns >= 1.0 && pwm_period_ns <= 1e3 * plant.period_us,
            "accepted PWM period of " + std::to_string(pwm_period_ns) + " ns (period " + std::to_string(plant.period_us) +
                " us)");
    require(pwm_period_ns / plant.board.pwm_duty_steps >= 1.0, "accepted sub-nanosecond PWM duty steps");
  }
  if (plant.has_table) require(plant.table_range_us >= plant.period_us, "accepted a table range below the period");
  d::DesignResult design;
  try {
    design = d::synthesize(plant);
  } catch (const d::DesignError&) {
    return 0;
  }
  const std::string bad = oneshot::util::first_non_finite(d::design_json(plant, design));
  require(bad.empty(), "accepted plant, design JSON field '" + bad + "' is NaN, infinite or null");
  const Eigen::MatrixXd phi = eigen_of(design.phi_h);
  const Eigen::MatrixXd k = eigen_of(design.kalman_gain);
  const Eigen::MatrixXd c = eigen_of(plant.c);
  const Eigen::MatrixXd eye = Eigen::MatrixXd::Identity(phi.rows(), phi.cols());
  const double estimator = spectral_radius((eye - k * c) * phi);
  require(estimator < 1.0, "accepted plant with an unstable estimator: radius " + std::to_string(estimator));
  if (design.lqr_available) {
    // The regulated plant states (the exogenous disturbance states are cancelled, not regulated).
    const Eigen::Index np = phi.rows() - static_cast<Eigen::Index>(design.exogenous_states);
    const Eigen::MatrixXd loop =
        phi.topLeftCorner(np, np) - eigen_of(design.gamma_h).topRows(np) * eigen_of(design.l).leftCols(np);
    const double radius = spectral_radius(loop);
    require(radius < 1.0, "accepted plant with an unstable closed loop: radius " + std::to_string(radius));
  }
  if (design.deadbeat) {
    // A deadbeat observer: ((I - K_db C) Phi)^n = 0, recomputed here with Eigen on the scale
    // the design step states its claim on (max(1, max|Phi|^n), lut_gen/src/feedforward_deadbeat.cpp,
    // which accepts 1e-8); 1e-6 leaves room for the two computations' rounding. Relative to
    // max|Phi^n| instead, a 12-state plant reached 1.6e-4 (tests/fuzz/corpus/plant/deadbeat_scale.json).
    const Eigen::MatrixXd kdb = eigen_of(design.deadbeat_gain);
    require(kdb.cwiseAbs().maxCoeff() > 0, "deadbeat observer available with a zero gain");
    const Eigen::MatrixXd e = (eye - kdb * c) * phi;
    Eigen::MatrixXd power = eye;
    for (Eigen::Index i = 0; i < phi.rows(); ++i) power = power * e;
    const double scale = std::max(1.0, std::pow(phi.cwiseAbs().maxCoeff(), static_cast<double>(phi.rows())));
    const double residual = power.cwiseAbs().maxCoeff() / scale;
    require(std::isfinite(residual) && residual < 1e-6,
            "deadbeat observer available, but ((I - K C) Phi)^n is not 0: " + std::to_string(residual));
  }
  return 0;
}
