/// @file petc_modal.cpp
/// @brief Block-diagonal basis of a NUMRE model (petc_modal.hpp).
#include "petc_modal.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "oneshot/design/dense_ops.hpp"

namespace oneshot::sim::petc {

namespace {

/// X (o × b) with A_oo X − X D = R by the Kronecker form (I ⊗ A_oo − Dᵀ ⊗ I) vec X = vec R
/// (vec stacks columns): column c reads A_oo x_c − Σ_r D_rc x_r = r_c.
DenseMatrix sylvester(const DenseMatrix& a_oo, const DenseMatrix& d, const DenseMatrix& r) {
  const std::size_t o = a_oo.rows, b = d.rows;
  DenseMatrix k = DenseMatrix::zeros(o * b, o * b);
  DenseMatrix rhs = DenseMatrix::zeros(o * b, 1);
  for (std::size_t c = 0; c < b; ++c) {
    for (std::size_t i = 0; i < o; ++i) {
      rhs(c * o + i, 0) = r(i, c);
      for (std::size_t j = 0; j < o; ++j) k(c * o + i, c * o + j) = a_oo(i, j);
      for (std::size_t q = 0; q < b; ++q) k(c * o + i, q * o + i) -= d(q, c);
    }
  }
  const design::SolveResult s = design::solve(k, rhs);
  if (!s.ok) throw std::invalid_argument("petc modal form: a diagonal block shares an eigenvalue with the rest");
  DenseMatrix x = DenseMatrix::zeros(o, b);
  for (std::size_t c = 0; c < b; ++c)
    for (std::size_t i = 0; i < o; ++i) x(i, c) = s.x(c * o + i, 0);
  return x;
}

}  // namespace

BlockDiagonalModel block_diagonal_model(const EstimatorModel& m, std::size_t block, std::size_t leading) {
  const std::size_t n = m.a.rows;
  if (leading == 0) leading = n;
  if (block == 0 || n == 0 || leading > n || leading % block != 0 || m.a.cols != n)
    throw std::invalid_argument("petc modal form: " + std::to_string(leading) + " of " + std::to_string(n) +
                                " states do not split into blocks of " + std::to_string(block));
  // A's leading part (the plant) is block-diagonalized; the rest (the disturbance) keeps its
  // coupling column into it: A' = [[D, T_p⁻¹ A_pd], [0, A_dd]].
  const DenseMatrix a_pp = design::block(m.a, 0, 0, leading, leading);
  DenseMatrix t = design::identity(n);
  DenseMatrix d = m.a;
  for (std::size_t i = 0; i < leading; ++i)
    for (std::size_t j = 0; j < leading; ++j) d(i, j) = 0.0;
  for (std::size_t s = 0; s < leading; s += block) {
    std::vector<std::size_t> other;
    for (std::size_t i = 0; i < leading; ++i)
      if (i < s || i >= s + block) other.push_back(i);
    const std::size_t o = other.size();
    DenseMatrix a_oo = DenseMatrix::zeros(o, o), r = DenseMatrix::zeros(o, block);
    for (std::size_t i = 0; i < o; ++i) {
      for (std::size_t j = 0; j < o; ++j) a_oo(i, j) = a_pp(other[i], other[j]);
      for (std::size_t c = 0; c < block; ++c) r(i, c) = -a_pp(other[i], s + c);
    }
    const DenseMatrix d_j = design::block(a_pp, s, s, block, block);
    design::set_block(d, s, s, d_j);
    const DenseMatrix x = o == 0 ? DenseMatrix::zeros(0, block) : sylvester(a_oo, d_j, r);
    for (std::size_t i = 0; i < o; ++i)
      for (std::size_t c = 0; c < block; ++c) t(other[i], s + c) = x(i, c);
  }
  // Entries that vanish in exact arithmetic (upstream of a block) come out as rounding dust.
  design::flush_tiny(t, 1e-14);
  const design::SolveResult inv = design::solve(t, design::identity(n));
  if (!inv.ok) throw std::invalid_argument("petc modal form: T is singular");
  // The coupling column of the rest: T_p⁻¹ A_pd (rows of the leading part).
  const DenseMatrix coupled = inv.x * m.a;
  for (std::size_t i = 0; i < leading; ++i)
    for (std::size_t j = leading; j < n; ++j) d(i, j) = coupled(i, j);
  BlockDiagonalModel out;
  out.t = t;
  out.t_max = design::max_abs(t);
  const DenseMatrix ad = inv.x * m.a * t;
  out.residual = design::max_abs(ad - d) / std::max(1e-300, design::max_abs(m.a));
  if (!(out.residual <= 1e-10))
    throw std::invalid_argument("petc modal form: T^-1 A T is not block diagonal (residual " +
                                std::to_string(out.residual) + "): A is not block triangular");
  design::flush_tiny(d, 1e-15);
  out.model = m;
  out.model.a = d;
  out.model.b = inv.x * m.b;
  out.model.b_w = inv.x * m.b_w;
  out.model.c = m.c * t;
  out.model.c_bar = m.c_bar * t;
  return out;
}

}  // namespace oneshot::sim::petc
