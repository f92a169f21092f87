/// @file controller_synthesis.hpp
/// @brief The design step: plant description → discrete model, LQR, Kalman, observers.
///
/// Everything here is computed from the plant description, never typed in:
///  * Φ(h), Γ(h), Q_d(h) by the core's generic routine (double), with the continuous
///    process intensity Q_c = Qn / h: the white noise whose integral over one period
///    (without dynamics) is the identified per-period covariance Qn.
///  * Sampled cost (Åström & Wittenmark, ch. 11), via Van Loan with F = [[A, B], [0, 0]]:
///      exp([[−Fᵀ, W], [0, F]] h) = [[·, E₁₂], [0, E₂₂]],  E₂₂ᵀE₁₂ = [[Q1, Q12], [Q12ᵀ, Q2]],
///    W = blkdiag(Q1c, Q2c).
///  * LQR with cross term: Ã = Φ − Γ Q2⁻¹ Q12ᵀ, Q̃1 = Q1 − Q12 Q2⁻¹ Q12ᵀ, DARE on
///    (Ã, Γ Q2⁻¹ Γᵀ, Q̃1), L = (Q2 + ΓᵀSΓ)⁻¹ (ΓᵀSΦ + Q12ᵀ), u = −L x.
///  * Steady-state Kalman filter for period h with Q_d(h): prior P from the dual DARE,
///    K = P Cᵀ (C P Cᵀ + R)⁻¹, posterior (I − K C) P.
///  * Set-point feed-forward [[A, B], [C, 0]] [N_x; N_u] = [0; I] (p = m).
///  * Current deadbeat observer (p = 1): K_db = Φⁿ O⁻¹ e_n, O = [CΦ; CΦ²; …; CΦⁿ].
#pragma once

#include <stdexcept>
#include <string>

#include "oneshot/design/dense_matrix.hpp"
#include "oneshot/design/plant_description.hpp"

namespace oneshot::design {

/// The design step could not produce a valid controller (names what failed).
class DesignError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Results of the design step (double precision, run-time sizes).
struct DesignResult {
  double period_s = 0;                 ///< h (s).
  DenseMatrix phi_h;                   ///< Φ(h).
  DenseMatrix gamma_h;                 ///< Γ(h).
  DenseMatrix qd_h;                    ///< Q_d(h) (exact, from Q_c).
  DenseMatrix qc;                      ///< Q_c = Qn/h (V²/s).
  DenseMatrix q1, q12, q2;             ///< Sampled cost weights.
  DenseMatrix riccati;                 ///< LQR Riccati solution S.
  DenseMatrix l;                       ///< LQR gain (u = −L x).
  double closed_loop_radius = 0;       ///< Spectral radius of Φ(h) − Γ(h) L.
  DenseMatrix kalman_prior;            ///< Steady-state prior covariance.
  DenseMatrix kalman_posterior;        ///< Steady-state posterior covariance.
  DenseMatrix kalman_gain;             ///< Steady-state gain K.
  double estimator_radius = 0;         ///< Spectral radius of (I − K C) Φ(h).
  bool tracking = false;               ///< Set-point feed-forward available (p = m).
  DenseMatrix nx, nu;                  ///< x_ref = N_x r, u_ref = N_u r.
  bool deadbeat = false;               ///< Deadbeat observer available (p = 1, observable).
  DenseMatrix deadbeat_gain;           ///< K_db.
  DenseMatrix p0;                      ///< Initial covariance (given, or the steady-state prior).
  DenseMatrix q_constant;              ///< Per-step Q of the original design (= Qn).
  DenseMatrix r;                       ///< R.
  std::vector<double> u_min, volts_per_step, steps_per_volt;  ///< Actuator model.
  std::int32_t actuator_steps = 0;     ///< Actuator resolution.
  std::vector<double> y_offset, volts_per_code;  ///< Sensor model.
};

/// Runs the design step; DesignError when the plant admits no stabilising design.
DesignResult synthesize(const PlantDescription& plant);

}  // namespace oneshot::design
