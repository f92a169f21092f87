/// @file petc_modal.hpp
/// @brief The NUMRE model in a block-diagonal basis (issue 25): the cascade and the span
///        table then cost O(n) per step instead of O(nnz(A)).
///
/// The augmented HDD model is block triangular in 2 × 2 blocks (sections in series, the
/// disturbance entering at the input). With T unit block triangular (T_jj = I) such that
///     A T = T D,   D = blockdiag(A_11, …, A_bb)   (A's own diagonal blocks, unchanged),
/// the model in z = T⁻¹ x is
///     A' = D (with `leading` < n: [[D_p, T_p⁻¹A_pd], [0, A_dd]]),  B' = T⁻¹ B,  B_w' = T⁻¹ B_w,  C' = C T,  C̄' = C̄ T
/// (same transfer functions u → y, u → d̂, w → y; W and V unchanged). Block column j of T
/// solves the Sylvester equation over the other rows o (A_oo X − X A_jj = −A_oj), solvable
/// when A_jj shares no eigenvalue with the rest (distinct poles); for a block-triangular A
/// its entries upstream of j vanish, so T keeps the triangular pattern.
/// x̂ = T ẑ maps back; ŷ = C' ẑ and d̂ = C̄' ẑ need no map. Only the plant part is
/// block-diagonalized for the HDD model (`leading` = 10): the disturbance block stays coupled
/// by one column, since fully decoupling it needs T entries ~10⁸ (x_d is ~10⁻⁶ of x_p) and
/// its covariance then loses ~10⁻³ in float (measured), while T_p stays ≤ 1.33.
#pragma once

#include <cstddef>

#include "petc_design.hpp"

namespace oneshot::sim::petc {

/// A model in the block-diagonal basis and what the transform reports.
struct BlockDiagonalModel {
  EstimatorModel model;       ///< A' = D, B', B_w', C', C̄' (W, V as given).
  DenseMatrix t;              ///< T: x = T z.
  double residual = 0;        ///< max |T⁻¹ A T − D| / max |A| (rounding of the design in double).
  double t_max = 0;           ///< max |T_ij| (how far the basis is from the original one).
};

/// The block-diagonal form of `m` with `block` × `block` diagonal blocks; std::invalid_argument
/// when n is not a multiple of `block`, a Sylvester system is singular (a shared eigenvalue)
/// or the residual exceeds 1e-10 (A not block triangular).
/// `leading` (0: all n) is how many leading states are block-diagonalized: the states after
/// them keep A's coupling from them into the leading part.
BlockDiagonalModel block_diagonal_model(const EstimatorModel& m, std::size_t block = 2, std::size_t leading = 0);

}  // namespace oneshot::sim::petc
