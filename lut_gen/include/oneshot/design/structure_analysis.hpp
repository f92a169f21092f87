/// @file structure_analysis.hpp
/// @brief Structural (graph) analysis of a plant: which entries of Φ(t), Γ(t), Q_d(t) are
///        exactly 0 or 1 for every t, and the exact 0/1 entries of the design constants.
///
/// With reach(i, j) = "a walk of length ≥ 1 from state j to state i in the graph of A":
///   Φ_ij ≡ 0 iff i ≠ j and not reach(i, j);  Φ_ii ≡ 1 iff i lies on no cycle;
///   Γ = Σ_k A^k B t^{k+1}/(k+1)!: non-zero pattern nz(Φ)·nz(B);
///   Q_d = ∫ Φ Q_c Φᵀ: non-zero pattern nz(Φ)·nz(Q_c)·nz(Φ)ᵀ, never structurally one.
/// These hold for the exact functions and for every rounded evaluation of them (no
/// arithmetic turns structural zeros into non-zeros), so the kernels may skip them.
#pragma once

#include <array>
#include <cstdint>
#include <string>

#include "oneshot/design/controller_synthesis.hpp"
#include "oneshot/design/plant_description.hpp"

namespace oneshot::design {

/// Run-time form of oneshot::Pattern (bit i*cols + j, in four 64-bit words).
struct PatternMask {
  std::size_t rows = 0;                  ///< Rows.
  std::size_t cols = 0;                  ///< Columns.
  std::array<std::uint64_t, 4> zero{};   ///< Structural zeros.
  std::array<std::uint64_t, 4> one{};    ///< Structural ones.
  /// Entry (i, j) is structurally zero.
  bool is_zero(std::size_t i, std::size_t j) const { return test(zero, i * cols + j); }
  /// Entry (i, j) is structurally one.
  bool is_one(std::size_t i, std::size_t j) const { return test(one, i * cols + j); }
  /// Entry (i, j) carries data.
  bool is_free(std::size_t i, std::size_t j) const { return !is_zero(i, j) && !is_one(i, j); }
  /// Marks entry (i, j) structurally zero.
  void set_zero(std::size_t i, std::size_t j) { set(zero, i * cols + j); }
  /// Marks entry (i, j) structurally one.
  void set_one(std::size_t i, std::size_t j) { set(one, i * cols + j); }
  /// C++ spelling: oneshot::Pattern<rows, cols, zero₀, one₀[, zero₁, one₁, …]> (as many
  /// word pairs as rows·cols needs; refused beyond 256 entries).
  std::string cpp_type() const;

 private:
  static bool test(const std::array<std::uint64_t, 4>& w, std::size_t b) {
    return b < 256 && ((w[b / 64] >> (b % 64)) & 1U) != 0U;
  }
  static void set(std::array<std::uint64_t, 4>& w, std::size_t b) { w.at(b / 64) |= std::uint64_t{1} << (b % 64); }
};

/// Patterns of every matrix the control job uses.
struct PlantPatterns {
  PatternMask phi;                ///< Φ(t).
  PatternMask gamma;              ///< Γ(t).
  PatternMask qd;                 ///< Q_d(t).
  PatternMask constant_q;         ///< The constant per-step Q.
  PatternMask output;             ///< C.
  PatternMask feedback;           ///< L.
  PatternMask state_feedforward;  ///< N_x.
  PatternMask input_feedforward;  ///< N_u.
};

/// Exact 0 / 1 entries of a constant matrix.
PatternMask constant_pattern(const DenseMatrix& m);

/// Structural analysis of the plant and its design.
PlantPatterns analyse_structure(const PlantDescription& plant, const DesignResult& design);

}  // namespace oneshot::design
