/// @file petc_modal_test.cpp
/// @brief The block-diagonal basis of the NUMRE model (petc_modal.hpp): same transfer
///        functions u → y, u → d̂, w → y (Markov parameters against the original model), T
///        unit block triangular, A' = A's own diagonal blocks exactly, and the models it
///        must refuse (coupled both ways, a shared eigenvalue).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "oneshot/design/dense_ops.hpp"
#include "petc_modal.hpp"
#include "petc_sim.hpp"
#include "support/measured_text.hpp"

namespace {

using namespace oneshot::sim::petc;

using oneshot::test::sci;

/// max_k |r A^k c − r' A'^k c'| / max_k |r A^k c|, k = 0 … steps − 1.
double markov_error(const DenseMatrix& a, const DenseMatrix& r, const DenseMatrix& c, const DenseMatrix& a2,
                    const DenseMatrix& r2, const DenseMatrix& c2, std::size_t steps) {
  DenseMatrix v = c, v2 = c2;
  double worst = 0, scale = 0;
  for (std::size_t k = 0; k < steps; ++k) {
    const double h = (r * v)(0, 0), h2 = (r2 * v2)(0, 0);
    worst = std::max(worst, std::abs(h - h2));
    scale = std::max(scale, std::abs(h));
    v = a * v;
    v2 = a2 * v2;
  }
  return scale > 0 ? worst / scale : worst;  // u → d̂ is zero in both: the absolute error
}

TEST(PetcModal, SameTransferFunctionsAsTheAugmentedModel) {
  const PetcSetup s = make_setup(PetcOptions{});
  const EstimatorModel& m = s.plant.augmented;
  const BlockDiagonalModel& z = s.node_model;  // the plant's ten states block-diagonalized
  const std::size_t steps = 465;  // K + 1: every lag a run can see
  const double uy = markov_error(m.a, m.c, m.b, z.model.a, z.model.c, z.model.b, steps);
  const double ud = markov_error(m.a, m.c_bar, m.b, z.model.a, z.model.c_bar, z.model.b, steps);
  const double wy = markov_error(m.a, m.c, m.b_w, z.model.a, z.model.c, z.model.b_w, steps);
  const double wd = markov_error(m.a, m.c_bar, m.b_w, z.model.a, z.model.c_bar, z.model.b_w, steps);
  RecordProperty("u_to_y_rel_err", sci(uy));
  RecordProperty("u_to_d_rel_err", sci(ud));
  RecordProperty("w_to_y_rel_err", sci(wy));
  RecordProperty("w_to_d_rel_err", sci(wd));
  RecordProperty("residual", sci(z.residual));
  RecordProperty("t_max", sci(z.t_max));
  // Measured 1.8e-15 (u → y), 1.9e-15 (w → y); u → d̂ and w → d̂ exactly equal (C̄' = C̄ and
  // the disturbance rows of A are A's); residual 2.5e-21.
  EXPECT_LT(uy, 1e-14);
  EXPECT_EQ(ud, 0.0);
  EXPECT_LT(wy, 1e-14);
  EXPECT_EQ(wd, 0.0);
  EXPECT_LT(z.residual, 1e-18);
  EXPECT_EQ(z.model.w, m.w);
  EXPECT_EQ(z.model.v, m.v);
}

TEST(PetcModal, UnitBlockTriangularBasisKeepsTheSections) {
  const PetcSetup s = make_setup(PetcOptions{});
  const DenseMatrix& a = s.plant.augmented.a;
  const BlockDiagonalModel& z = s.node_model;
  const std::size_t n = a.rows, plant = 10;
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = 0; j < n; ++j) {
      const bool same_block = i / 2 == j / 2;
      if (i < plant && j < plant) {
        // The plant part of A' is A's own 2 × 2 sections, bit for bit, and nothing else.
        EXPECT_EQ(z.model.a(i, j), same_block ? a(i, j) : 0.0) << i << "," << j;
        if (same_block) {
          EXPECT_EQ(z.t(i, j), i == j ? 1.0 : 0.0) << i << "," << j;
        }
      } else if (i >= plant) {
        EXPECT_EQ(z.model.a(i, j), a(i, j)) << i << "," << j;  // the disturbance rows unchanged
        EXPECT_EQ(z.t(i, j), i == j ? 1.0 : 0.0) << i << "," << j;
      } else {
        EXPECT_EQ(z.t(i, j), 0.0) << i << "," << j;  // T = blockdiag(T_p, I)
      }
    }
  EXPECT_LT(z.t_max, 2.0);  // well conditioned: measured 1.33
}

/// A 4-state model of two 2 × 2 blocks coupled by `up` (block 0 → 1) and `down` (1 → 0).
EstimatorModel coupled(double up, double down, double pole1) {
  EstimatorModel m;
  m.a = DenseMatrix{4, 4, {0.9, 0.1, 0, down, -0.1, 0.9, 0, 0, up, 0, pole1, 0.2, 0, 0, -0.2, pole1}};
  m.b = DenseMatrix{4, 1, {1, 0, 0, 0}};
  m.b_w = DenseMatrix{4, 1, {0, 0, 0, 1}};
  m.c = DenseMatrix{1, 4, {0, 0, 1, 0}};
  m.c_bar = DenseMatrix{1, 4, {0, 0, 0, 0}};
  return m;
}

TEST(PetcModal, RefusesWhatItCannotBlockDiagonalize) {
  EXPECT_NO_THROW(static_cast<void>(block_diagonal_model(coupled(0.5, 0.0, 0.5))));  // one way: fine
  EXPECT_THROW(static_cast<void>(block_diagonal_model(coupled(0.5, 0.3, 0.5))), std::invalid_argument);  // both ways
  // Block 1 with the eigenvalues of block 0 (0.9 ± 0.1i, rotation of the same size): singular.
  EstimatorModel same = coupled(0.5, 0.0, 0.9);
  same.a(2, 3) = 0.1;
  same.a(3, 2) = -0.1;
  EXPECT_THROW(static_cast<void>(block_diagonal_model(same)), std::invalid_argument);
  EXPECT_THROW(static_cast<void>(block_diagonal_model(coupled(0.5, 0.0, 0.5), 3)), std::invalid_argument);
}

}  // namespace
