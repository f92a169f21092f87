/// @file dropping_plant.hpp
/// @brief The dropping study's plant (lut_gen/plants/sinopoli_dropping.json, or another
///        discrete 3-state, 1-input, 1-output plant file), its design and the arrival law.
#pragma once

#include <cstddef>
#include <string>

#include "mare.hpp"
#include "oneshot/design/controller_synthesis.hpp"
#include "oneshot/design/plant_description.hpp"
#include "oneshot/matrix.hpp"

namespace oneshot::dropping {

constexpr std::size_t kN = 3;  ///< States of the study's plant.
constexpr std::size_t kM = 1;  ///< Inputs.
constexpr std::size_t kP = 1;  ///< Outputs.

/// The plant, its design step and the fixed-size matrices the study runs on.
struct DroppingPlant {
  design::PlantDescription plant;     ///< As parsed.
  design::DesignResult design;        ///< LAPACK design step (DLQR gain L).
  Matrix<double, kN, kN> phi;         ///< Φ per step.
  Matrix<double, kN, kM> gamma;       ///< Γ per step.
  Matrix<double, kP, kN> c;           ///< C.
  Matrix<double, kN, kN> q;           ///< Q per step.
  Matrix<double, kP, kP> r;           ///< R.
  Matrix<double, kN, kN> p0;          ///< P₀ (prior of x₀; also the law of x₀).
  Matrix<double, kM, kN> l;           ///< u = −L x̂ (DLQR(Φ, Γ, Q1, Q2)).
  Matrix<double, kN, kN> q1;          ///< Per-step state cost weight.
  Matrix<double, kM, kM> q2;          ///< Per-step input cost weight.
  double rho = 0;                     ///< Spectral radius of Φ.
  double lambda_sys = 0;              ///< 1 − 1/ρ² (0 when ρ < 1).
  /// The MARE's view of the plant.
  MareModel<kN, kP> mare() const { return {phi, q, c, r}; }
};

/// Loads `path` (empty: the built-in sinopoli_dropping.json) and designs it; std::runtime_error
/// naming the file when it is not a discrete plant with n = 3, m = 1, p = 1 and a cost.
DroppingPlant load_dropping_plant(const std::string& path);

/// λ(T_hold) = (1 − ε) Σ_{t=0}^{T_hold−1} e^{−D} D^t / t!  (brief §3, eq 10 corrected).
double arrival_probability(int t_hold, double mean_delay_periods, double loss);

/// Poisson pmf e^{−D} D^t / t!.
double poisson_pmf(int t, double mean);

/// D such that (1 − ε) e^{−D} = λ (T_hold = 1): D = −ln(λ / (1 − ε)); invalid_argument outside (0, 1 − ε].
double delay_for_lambda(double lambda, double loss);

/// The built-in plant file's text (lut_gen/plants/sinopoli_dropping.json, read once; its digest
/// names the plant in sweep shards).
const std::string& dropping_plant_json();

}  // namespace oneshot::dropping
