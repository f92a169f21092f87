/// @file sod_model.hpp
/// @brief The send-on-delta study's plant per period, from its plant file
///        (lut_gen/plants/send_on_delta_oscillator.json; brief §1).
#pragma once

#include <cstdint>
#include <string>

#include "oneshot/design/dense_matrix.hpp"
#include "oneshot/engine/plant_model.hpp"
#include "oneshot/matrix.hpp"

namespace oneshot::sod {

inline constexpr std::size_t kStates = 2;   ///< n.
inline constexpr std::size_t kInputs = 1;   ///< m.
inline constexpr std::size_t kNodes = 2;    ///< p: one sensor node per output.

/// The plant sampled at T (A_d, B_d, Q_d by the design step's Van Loan), C, diagonal R.
struct SodModel {
  std::string plant_name;                      ///< From the plant file.
  std::string plant_source;                    ///< File it came from.
  std::int32_t period_us = 0;                  ///< T.
  Matrix<double, kStates, kStates> a_d;        ///< A_d = e^{AT}.
  Matrix<double, kStates, kInputs> b_d;        ///< B_d.
  Matrix<double, kStates, kStates> q_d;        ///< Q_d (from the intensity Q_c).
  Matrix<double, kNodes, kStates> c;           ///< C (node i reads output i).
  Vector<double, kNodes> r_diag;               ///< R_ii per sample.
  design::DenseMatrix phi, qd, cm;             ///< The same, run-time sized, for the design step.
  engine::DiscreteModel discrete;              ///< Φ = A_d, Γ = B_d, C, Q = Q_d per T: the engine's plant.
  /// T in seconds.
  double period_s() const { return period_us * 1e-6; }
};

/// The plant file shipped with the study (lut_gen/plants/send_on_delta_oscillator.json).
std::string default_sod_plant_path();

/// Loads and samples a plant file; std::invalid_argument when it is not a continuous or
/// discrete plant with n = 2, m = 1, p = 2 and diagonal R (each problem named).
SodModel load_sod_model(const std::string& path);

}  // namespace oneshot::sod
