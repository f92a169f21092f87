/// @file structure_analysis.cpp
/// @brief Graph analysis of the plant (see structure_analysis.hpp).
#include "oneshot/design/structure_analysis.hpp"

#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

namespace oneshot::design {
namespace {

using BoolMatrix = std::vector<std::vector<bool>>;

BoolMatrix nonzero(const DenseMatrix& m) {
  BoolMatrix b(m.rows, std::vector<bool>(m.cols, false));
  for (std::size_t i = 0; i < m.rows; ++i)
    for (std::size_t j = 0; j < m.cols; ++j) b[i][j] = m(i, j) != 0.0;
  return b;
}

BoolMatrix bool_product(const BoolMatrix& a, const BoolMatrix& b) {
  const std::size_t r = a.size();
  const std::size_t k = b.size();
  const std::size_t c = k == 0 ? 0 : b[0].size();
  BoolMatrix out(r, std::vector<bool>(c, false));
  for (std::size_t i = 0; i < r; ++i)
    for (std::size_t j = 0; j < c; ++j)
      for (std::size_t l = 0; l < k && !out[i][j]; ++l) out[i][j] = a[i][l] && b[l][j];
  return out;
}

BoolMatrix transposed(const BoolMatrix& a) {
  BoolMatrix t(a.empty() ? 0 : a[0].size(), std::vector<bool>(a.size(), false));
  for (std::size_t i = 0; i < a.size(); ++i)
    for (std::size_t j = 0; j < a[i].size(); ++j) t[j][i] = a[i][j];
  return t;
}

PatternMask from_nonzero(const BoolMatrix& nz, std::size_t rows, std::size_t cols) {
  PatternMask p{rows, cols, {}, {}};
  for (std::size_t i = 0; i < rows; ++i)
    for (std::size_t j = 0; j < cols; ++j)
      if (!nz[i][j]) p.set_zero(i, j);
  return p;
}

}  // namespace

std::string PatternMask::cpp_type() const {
  if (rows * cols > 256) throw DesignError("pattern of " + std::to_string(rows) + "x" + std::to_string(cols) +
                                           " entries exceeds kMaxPatternEntries (256)");
  const std::size_t words = std::max<std::size_t>(1, (rows * cols + 63) / 64);
  std::string out = "::oneshot::Pattern<" + std::to_string(rows) + ", " + std::to_string(cols);
  for (std::size_t w = 0; w < words; ++w) {
    char buf[64];
    std::snprintf(buf, sizeof buf, ", 0x%llxULL, 0x%llxULL", static_cast<unsigned long long>(zero[w]),
                  static_cast<unsigned long long>(one[w]));
    out += buf;
  }
  return out + ">";
}

PatternMask constant_pattern(const DenseMatrix& m) {
  PatternMask p{m.rows, m.cols, {}, {}};
  for (std::size_t i = 0; i < m.rows; ++i)
    for (std::size_t j = 0; j < m.cols; ++j) {
      if (m(i, j) == 0.0) p.set_zero(i, j);
      if (m(i, j) == 1.0) p.set_one(i, j);
    }
  return p;
}

PlantPatterns analyse_structure(const PlantDescription& plant, const DesignResult& design) {
  const std::size_t n = plant.n();
  const std::size_t m = plant.m();
  // reach = nz(A) ∨ nz(A)² ∨ … ∨ nz(A)ⁿ (walks of length 1 … n).
  const BoolMatrix a = nonzero(plant.a);
  BoolMatrix reach = a;
  BoolMatrix power = a;
  for (std::size_t k = 2; k <= n; ++k) {
    power = bool_product(power, a);
    for (std::size_t i = 0; i < n; ++i)
      for (std::size_t j = 0; j < n; ++j) reach[i][j] = reach[i][j] || power[i][j];
  }
  BoolMatrix phi_nz = reach;
  for (std::size_t i = 0; i < n; ++i) phi_nz[i][i] = true;

  PlantPatterns p;
  p.phi = from_nonzero(phi_nz, n, n);
  for (std::size_t i = 0; i < n; ++i)
    if (!reach[i][i]) p.phi.set_one(i, i);
  p.gamma = from_nonzero(bool_product(phi_nz, nonzero(plant.b)), n, m);
  p.qd = from_nonzero(bool_product(bool_product(phi_nz, nonzero(design.qc)), transposed(phi_nz)), n, n);
  p.constant_q = constant_pattern(design.q_constant);
  p.output = constant_pattern(plant.c);
  p.feedback = constant_pattern(design.l);
  p.state_feedforward = constant_pattern(design.nx);
  p.input_feedforward = constant_pattern(design.nu);
  return p;
}

}  // namespace oneshot::design
