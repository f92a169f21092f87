/// @file c_job_variant.hpp
/// @brief One variant of the generated C job (number format × sub-grid policy): the half
///        Kalman filter, the one-shot prediction, the control law and the converters of the
///        C++ core (half_kalman.hpp, table_discretizer.hpp, control_law.hpp), unrolled over
///        the plant's structure, with every format and table index fixed at generation time.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "c_job/c_arith.hpp"
#include "c_job/c_writer.hpp"
#include "oneshot/design/controller_synthesis.hpp"
#include "oneshot/design/plant_description.hpp"
#include "oneshot/design/structure_analysis.hpp"

namespace oneshot::design::cjob {

struct Q15PolyTable;  // q15_poly_table.hpp
struct FloatPoly;     // float_poly.hpp
struct Q15Member;     // q15_poly_table.hpp

/// A table as the generated code stores it: layout, and the values as C literals.
struct TableText {
  std::int32_t granularity_us = 0;          ///< g.
  std::int32_t range_us = 0;                ///< Covered range.
  std::vector<std::uint16_t> radix;         ///< Per level, finest first.
  std::vector<std::uint16_t> level_offset;  ///< First entry of each level.
  std::size_t entries = 0;                  ///< Stored entries.
  std::size_t slots = 0;                    ///< Free values per entry.
  std::vector<std::int16_t> phi_slot, gamma_slot, qd_slot;  ///< Slot maps (kSlotZero/kSlotOne/slot).
  std::string value_ctype;                  ///< C type of a stored value.
  std::vector<std::string> values;          ///< entries × slots literals, entry-major.
  std::vector<int> value_frac;              ///< Fixed: scale of each slot's values.
  std::vector<std::uint8_t> low, high;      ///< Residual polynomial degrees per slot.
  std::vector<std::vector<long long>> coeff_raw;      ///< Fixed: coefficients low … high.
  std::vector<std::vector<float>> coeff_float;        ///< Float: coefficients low … high.
  std::vector<int> residual_frac;           ///< Fixed: scale of each slot's coefficients.
  /// Float nearest: (range/g + 1) × slots literals, the triple at every grid point as the
  /// stored entries compose (float_grid.hpp); empty: compose at run time.
  std::vector<std::string> grid_values;
};

/// Everything one variant needs.
struct VariantSpec {
  std::string name;          ///< e.g. "fixed_table": C names oneshot_job_<name>_*.
  bool exact_subgrid = true; ///< SubGrid::kExact (else kNearest).
  const Arith* arith = nullptr;  ///< Number format.
  TableText table;           ///< Its table.
  /// Float only: Φ, Γ, Q_d as one polynomial in τ per entry (float_poly.hpp) instead of the table.
  bool polynomial = false;
};

/// Writes one variant: public declarations to `header`, definitions to `source`.
class VariantEmitter {
 public:
  VariantEmitter(const PlantDescription& plant, const DesignResult& design, const PlantPatterns& patterns,
                 const VariantSpec& spec);

  /// Declarations (state type, API) for oneshot_job.h.
  void header(CodeWriter& w) const;
  /// Definitions for oneshot_job.c.
  void source(CodeWriter& w);
  /// False when the variant cannot be generated for this plant (float_poly: no polynomial fits).
  bool available();
  /// Divisions the integer code could not replace by an exact reciprocal multiplication.
  int divisions() const { return divisions_; }
  /// Largest |τ| the job distinguishes (beyond it, the result equals that of ±this bound).
  std::int32_t tau_bound_us() const;

 private:
  // Naming.
  std::string fn(const std::string& what) const { return spec_.name + "_" + what; }
  std::string state_type() const { return "oneshot_job_" + spec_.name + "_t"; }
  std::string triple_type() const { return spec_.name + "_triple_t"; }
  std::string sat_param() const { return fixed() ? ", uint8_t *sat" : ""; }
  std::string sat_arg() const { return fixed() ? ", sat" : ""; }
  bool fixed() const { return spec_.arith->fixed(); }
  const Arith& ar() const { return *spec_.arith; }

  // Operands (structure-aware): triple `p` ("d", "e", …) entries, state entries.
  Val phi(const std::string& p, std::size_t i, std::size_t j) const;
  Val gamma(const std::string& p, std::size_t i, std::size_t j) const;
  Val qd(const std::string& p, std::size_t i, std::size_t j) const;
  Val cov(std::size_t i, std::size_t j) const;  // s->p
  Val state(std::size_t i) const;                // s->x
  Val input(std::size_t j) const;                // s->u
  Val design_const(Qty q, const DenseMatrix& m, const PatternMask& pat, std::size_t i, std::size_t j,
                   const std::string& what) const;
  static std::size_t upper_index(std::size_t n, std::size_t i, std::size_t j);
  // The free entries of Φ, Γ, Q_d (upper) in triple order: what the polynomial variants fit.
  std::vector<Q15Member> free_members() const;

  // Pieces of the discretizer (c_job_discretizer.cpp).
  void emit_table(CodeWriter& w) const;
  void emit_triple(CodeWriter& w) const;
  void emit_pick(CodeWriter& w, const std::string& dest, Qty q, std::int16_t slot, const std::string& raw_prefix,
                 bool residual) const;
  void emit_load(CodeWriter& w) const;
  void emit_grid(CodeWriter& w) const;
  bool grid() const { return !spec_.table.grid_values.empty(); }
  void emit_residual(CodeWriter& w) const;
  void emit_identity(CodeWriter& w) const;
  void emit_compose(CodeWriter& w) const;
  void emit_congruence(CodeWriter& w, const std::string& a, const std::vector<std::vector<Val>>& p,
                       const std::string& q, const std::string& out_prefix) const;
  void emit_in_range(CodeWriter& w);
  void emit_discretize(CodeWriter& w);
  // The q15 variants' interval polynomials, piecewise prediction and reciprocal (c_job_q15.cpp).
  void emit_q15_table(CodeWriter& w);
  void emit_q15_interval(CodeWriter& w) const;
  void emit_q15_advance(CodeWriter& w);
  void emit_q15_reciprocal(CodeWriter& w) const;
  // The float_poly variant's discretization (float_poly.cpp).
  void emit_float_poly(CodeWriter& w) const;
  void emit_float_poly_law(CodeWriter& w) const;
  // Pieces of the filter and the control law (c_job_filter.cpp).
  void emit_predict(CodeWriter& w) const;
  void emit_reciprocal(CodeWriter& w) const;
  void emit_correct(CodeWriter& w) const;
  void emit_code_value(CodeWriter& w, const std::string& dest, Qty q, const std::string& offset_what,
                       double offset, double step, const std::string& code) const;
  void emit_quantize(CodeWriter& w, std::size_t j, const std::string& u, const std::string& code) const;
  void emit_init(CodeWriter& w) const;
  void emit_run(CodeWriter& w);

  const PlantDescription& plant_;
  const DesignResult& design_;
  const PlantPatterns& pat_;
  VariantSpec spec_;
  std::size_t n_, m_, p_;
  std::vector<std::pair<std::size_t, std::size_t>> phi_free_, gamma_free_, qd_free_;  // qd: upper only
  int divisions_ = 0;
  std::shared_ptr<const Q15PolyTable> q15_table_;  // q15 variants: built by emit_q15_table
  std::shared_ptr<const FloatPoly> float_poly_;    // float_poly: built by available()
};

}  // namespace oneshot::design::cjob
