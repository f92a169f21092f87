/// @file float_poly.hpp
/// @brief The float_poly variant's discretization: every free entry of Φ, Γ, Q_d as one
///        polynomial in t = τ (µs) over the whole extended range 0 … 4·range,
///            v(τ) = Σ_{k ∈ E} c_k t^k,   c_0 = v(0) exactly,
///        fitted by least squares to the exact double discretization (GenericDiscretizer), of
///        the lowest degree, and then with every monomial dropped whose absence keeps the fit
///        within tolerance (so a chain of integrators keeps only its exact Taylor terms). The
///        coefficients are rounded to float once; the fit is checked with them, in double, on a
///        dense grid of integer τ against max |v| · 2^-21. No table, no composition: the job
///        evaluates a few products per entry. Plants whose entries need a degree above 6 (or
///        coefficients outside the normal float range) get no float_poly variant.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include "c_job/q15_poly_table.hpp"

namespace oneshot::design::cjob {

/// One stored polynomial (members with identical exact values share it).
struct FloatPolySlot {
  std::vector<std::size_t> members;  ///< Indices into FloatPoly::members.
  std::vector<int> exps;             ///< Powers of t with a non-zero coefficient, ascending.
  std::vector<float> coeff;          ///< Their coefficients (per µs^k).
  double max_error = 0;              ///< Measured max |fit − exact| (same unit as the entry).
  double max_value = 0;              ///< max |exact| over the domain.
};

/// The designed polynomials.
struct FloatPoly {
  std::vector<Q15Member> members;   ///< Triple entries, in triple order (Qty unused).
  std::vector<FloatPolySlot> slots;  ///< Stored polynomials.
  std::int32_t domain_us = 0;        ///< Largest τ evaluated (4·range: the table's clamp).
};

/// Relative fit tolerance: max |fit − exact| ≤ kFloatPolyTolerance · max |exact| per entry.
inline constexpr double kFloatPolyTolerance = 0x1p-21;

/// Designs the polynomials over 0 … domain_us; nothing when an entry does not fit.
std::optional<FloatPoly> design_float_poly(const PlantDescription& plant, const DesignResult& design,
                                           std::vector<Q15Member> members, std::int32_t domain_us);

}  // namespace oneshot::design::cjob
