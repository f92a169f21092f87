/// @file dare.hpp
/// @brief Discrete algebraic Riccati equation by ordered QZ on the symplectic pencil (host).
///
/// Solves, for the stabilising X = Xᵀ ⪰ 0,
///   X = AᵀXA − (AᵀXB + S)(R + BᵀXB)⁻¹(BᵀXA + Sᵀ) + Q,
/// the LQR equation of min Σ xᵀQx + 2xᵀSu + uᵀRu (the Kalman prior is the dual: A → Φᵀ,
/// B → Cᵀ, Q → Q_d, S = 0). With Ã = A − BR⁻¹Sᵀ, Q̃ = Q − SR⁻¹Sᵀ, G = BR⁻¹Bᵀ the pencil
///   [[Ã, 0], [−Q̃, I]] − λ [[I, G], [0, Ãᵀ]]
/// has the closed-loop eigenvalues and their reciprocals; LAPACK dgges reorders the
/// generalized Schur form so that the n eigenvalues inside the unit circle lead, and their
/// right deflating subspace [U₁; U₂] gives X = U₂U₁⁻¹ (Laub / Pappas–Laub–Sandell). QZ is
/// backward stable for the pencil; X and Q are first rescaled by s = √(‖Q̃‖/‖G‖) so that
/// the two blocks have comparable norms (a Kalman problem with Q ~ 1e−15 and CᵀR⁻¹C ~ 1e6
/// would otherwise lose Q below the pencil's rounding level). The relative residual is
/// always computed and returned; a solution with a residual above kDareResidualLimit is
/// reported as kInaccurate, never returned as good.
#pragma once

#include <string>

#include "oneshot/design/dense_matrix.hpp"

namespace oneshot::design {

/// Largest relative residual accepted from the solver.
inline constexpr double kDareResidualLimit = 1e-8;

/// Outcome of a DARE solve, ordered by severity (kOk mildest).
enum class DareStatus {
  kOk,              ///< Stabilising solution with a small residual.
  kInaccurate,      ///< Solved, but the residual is above kDareResidualLimit.
  kNoStabilizing,   ///< The pencil does not split n/n: eigenvalues on the unit circle (a
                    ///< unit-circle mode not controllable or not weighted), or not stabilizable.
  kSingularBasis,   ///< U₁ singular: no stabilising solution of this form.
  kSingularWeight,  ///< R not invertible.
  kFailed,          ///< LAPACK did not converge, or the data are not finite.
};

/// Human-readable name of a status.
const char* to_string(DareStatus s);

/// Solution and diagnostics.
struct DareSolution {
  DareStatus status = DareStatus::kFailed;  ///< Outcome.
  DenseMatrix x;                            ///< Stabilising solution (symmetrised) when kOk/kInaccurate.
  double residual = 0;                      ///< ‖residual‖_F / (‖Q‖_F + ‖AᵀXA‖_F + ‖correction‖_F).
  double unit_circle_distance = 0;          ///< min over pencil eigenvalues of ||λ| − 1|.
  double closed_loop_radius = 0;            ///< ρ(A − B K(X)), checked < 1 (kNoStabilizing otherwise).
};

/// Stabilising solution of the DARE above. S may be empty (no cross term).
DareSolution solve_dare(const DenseMatrix& a, const DenseMatrix& b, const DenseMatrix& q, const DenseMatrix& r,
                        const DenseMatrix& s = {});

/// Relative residual of X in the DARE (same measure as DareSolution::residual).
double dare_residual(const DenseMatrix& a, const DenseMatrix& b, const DenseMatrix& q, const DenseMatrix& r,
                     const DenseMatrix& s, const DenseMatrix& x);

}  // namespace oneshot::design
