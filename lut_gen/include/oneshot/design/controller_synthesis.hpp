/// @file controller_synthesis.hpp
/// @brief The design step: plant description → discrete model, LQR, Kalman, observers.
///
/// Run-time sized (any n ≤ kMaxStates, m, p ≤ 4: no template per size). Everything is
/// computed from the plant description, never typed in:
///  * Continuous plants: Φ(h), Γ(h), Q_d(h) by the scaled Taylor exponential of the core
///    (same operations, so the same bits as the core's generic routine), with the
///    continuous intensity Q_c = process_intensity, or Qn/h from a per-period covariance Qn
///    (the white noise whose integral over one period, without dynamics, is Qn), plus
///    B_w W_c B_wᵀ for a disturbance input. Discrete plants: Φ, Γ as given,
///    Q_d = Qn + B_w W B_wᵀ per step.
///  * Sampled cost (Åström & Wittenmark, ch. 11), via Van Loan with F = [[A, B], [0, 0]]:
///      exp([[−Fᵀ, W], [0, F]] h) = [[·, E₁₂], [0, E₂₂]],  E₂₂ᵀE₁₂ = [[Q1, Q12], [Q12ᵀ, Q2]],
///    W = blkdiag(Q1c, Q2c); or the discrete weights Q1 (or CᵀQyC), Q2 as given (Q12 = 0).
///  * LQR: stabilizability by PBH, then the DARE (dare.hpp) with cross term,
///    L = (Q2 + ΓᵀSΓ)⁻¹ (ΓᵀSΦ + Q12ᵀ), u = −L x. With an exogenous input-disturbance model
///    (sections form: Φ = [[Φ_p, Γ_p C_d], [0, A_d]]) the LQR is designed on the plant
///    states and the estimated disturbance is cancelled at the input: L = [L_p, C_d].
///  * Steady-state Kalman filter with Q_d(h): detectability by PBH, prior P from the dual
///    DARE, K = P Cᵀ (C P Cᵀ + R)⁻¹, posterior (I − K C) P, estimator (I − K C) Φ stable.
///  * Set-point feed-forward for the tracked outputs C_t (m of them):
///    [[A, B], [C_t, 0]] [N_x; N_u] = [0; I] (continuous), [[Φ − I, Γ], [C_t, 0]] (discrete).
///  * Current deadbeat observer (p = 1, (Φ, C) observable): K_db = Φⁿ O⁻¹ e_n,
///    O = [CΦ; CΦ²; …; CΦⁿ], accepted only when ((I − K_db C)Φ)ⁿ ≈ 0 is verified.
#pragma once

#include <stdexcept>
#include <string>
#include <vector>

#include "oneshot/design/dense_matrix.hpp"
#include "oneshot/design/plant_description.hpp"

namespace oneshot::design {

/// The design step could not produce a valid controller or estimator (names what failed).
class DesignError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Results of the design step (double precision, run-time sizes).
struct DesignResult {
  double period_s = 0;                 ///< h (s): the control period, or the discrete step T.
  DenseMatrix phi_h;                   ///< Φ(h).
  DenseMatrix gamma_h;                 ///< Γ(h).
  DenseMatrix gamma_w_h;               ///< Disturbance input per step (n×q): B_w (discrete), ∫₀ʰe^{As}ds B_w (continuous, w held); empty when q = 0.
  DenseMatrix qd_h;                    ///< Per-step process covariance of the Kalman design (exact Q_d(h) for continuous plants).
  DenseMatrix qc;                      ///< Continuous intensity Q_c (+ B_w W_c B_wᵀ) (unit²/s); empty for discrete plants.
  DenseMatrix q1, q12, q2;             ///< Per-step cost weights (sampled, or given with Q12 = 0); empty without a cost.

  bool lqr_available = false;          ///< Whether an LQR gain was designed (the plant has a cost).
  std::string lqr_unavailable_reason;  ///< Why not, when !lqr_available.
  DenseMatrix riccati;                 ///< LQR Riccati solution S (n_p×n_p: the plant states).
  DenseMatrix l;                       ///< LQR gain (m×n, u = −L x); zeros when unavailable.
  double closed_loop_radius = 0;       ///< Spectral radius of Φ_p − Γ_p L_p (the plant states).
  double lqr_residual = 0;             ///< Relative residual of the LQR DARE.
  std::size_t exogenous_states = 0;    ///< Trailing exogenous disturbance states (cancelled, not regulated).
  double exogenous_radius = 0;         ///< Spectral radius of their dynamics (0 when none).

  DenseMatrix kalman_prior;            ///< Steady-state prior covariance.
  DenseMatrix kalman_posterior;        ///< Steady-state posterior covariance.
  DenseMatrix kalman_gain;             ///< Steady-state gain K.
  double estimator_radius = 0;         ///< Spectral radius of (I − K C) Φ(h) (< 1, checked).
  double kalman_residual = 0;          ///< Relative residual of the Kalman DARE.

  bool tracking = false;               ///< Set-point feed-forward available.
  std::string tracking_unavailable_reason;  ///< Why not, when !tracking.
  std::vector<std::size_t> tracked_outputs;  ///< Outputs whose set-points enter (indices).
  DenseMatrix nx, nu;                  ///< x_ref = N_x r, u_ref = N_u r (r: one set-point per output; untracked columns 0).

  bool deadbeat = false;               ///< Deadbeat observer available (p = 1, observable, verified).
  std::string deadbeat_unavailable_reason;  ///< Why not, when !deadbeat.
  DenseMatrix deadbeat_gain;           ///< K_db (zeros when unavailable: never use it then).
  double deadbeat_residual = 0;        ///< max|((I − K_db C)Φ)ⁿ| / max(1, max|Φ|ⁿ).

  DenseMatrix p0;                      ///< Initial covariance (given, or the steady-state prior).
  DenseMatrix q_constant;              ///< Per-step Q of the original design (Qn, or Q_c h; + B_w W B_wᵀ).
  DenseMatrix r;                       ///< R.
  std::vector<double> u_min, u_max;    ///< Actuator range per input (board or `actuator`; empty when none).
  std::vector<double> volts_per_step, steps_per_volt;  ///< PWM model (board only).
  std::int32_t actuator_steps = 0;     ///< PWM resolution (board only, else 0).
  std::vector<double> y_offset, volts_per_code;  ///< ADC model (board only).
};

/// Runs the design step; DesignError when the plant admits no stabilising design or a
/// stable estimator, naming the cause.
DesignResult synthesize(const PlantDescription& plant);

}  // namespace oneshot::design
