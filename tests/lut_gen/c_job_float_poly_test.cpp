/// @file c_job_float_poly_test.cpp
/// @brief The float_poly variant's design (float_poly.hpp): one polynomial per free entry of
///        Φ, Γ, Q_d over 0 … 4·range, within its tolerance of the exact discretization, and
///        for the reference double integrator exactly the Taylor terms of the closed form.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "c_job/float_poly.hpp"
#include "oneshot/design/controller_synthesis.hpp"
#include "support/test_plants.hpp"

namespace oneshot::design {
namespace {

using cjob::FloatPoly;
using cjob::FloatPolySlot;
using cjob::Q15Member;
using cjob::Qty;

std::vector<Q15Member> reference_members() {
  // The reference board's free entries (structure_analysis): Φ(0,1), Γ(0,0), Γ(1,0), Q_d upper.
  return {{"phi", 0, 0, 1, Qty::kTransition},  {"gamma", 0, 0, 0, Qty::kInputGain},
          {"gamma", 1, 1, 0, Qty::kInputGain}, {"qd", 0, 0, 0, Qty::kCovariance},
          {"qd", 1, 0, 1, Qty::kCovariance},   {"qd", 2, 1, 1, Qty::kCovariance}};
}

TEST(CJobFloatPoly, ReferencePlantKeepsTheClosedFormTermsWithinTolerance) {
  // GIVEN the reference double integrator and its range of 4 × 50 ms
  const PlantDescription p = reference_plant();
  const DesignResult d = synthesize(p);
  const auto poly = cjob::design_float_poly(p, d, reference_members(), 200000);
  // WHEN the polynomials are designed THEN every entry fits, and shares where the values agree
  ASSERT_TRUE(poly.has_value());
  ASSERT_EQ(poly->slots.size(), 5U);  // Φ(0,1) = Γ(1,0) (the same a·t)
  const std::vector<std::vector<int>> terms = {{1}, {2}, {1, 3}, {2}, {1}};
  for (std::size_t s = 0; s < poly->slots.size(); ++s) {
    const FloatPolySlot& slot = poly->slots[s];
    SCOPED_TRACE(s);
    // Φ(τ) = [1 aτ; 0 1], Γ = [bτ²/2; aτ], Q_d: q00 ∝ τ³ plus a τ term, q01 ∝ τ², q11 ∝ τ:
    // the closed form's monomials only, no constant (Φ's free entry and Γ, Q_d vanish at 0).
    EXPECT_EQ(slot.exps, terms[s]);
    EXPECT_GT(slot.max_value, 0.0);
    // The measured fit error (float coefficients, 2002 check points) is below the design
    // tolerance, and for the exact polynomial form near float rounding (≤ 2.8e-8 measured).
    EXPECT_LE(slot.max_error, cjob::kFloatPolyTolerance * slot.max_value);
    EXPECT_LE(slot.max_error, 1e-7 * slot.max_value);
  }
  EXPECT_EQ(poly->slots[0].members.size(), 2U);
}

TEST(CJobFloatPoly, ShortDomainNeedsNoHigherDegree) {
  // The same entries over a single period: still the closed form's terms.
  const PlantDescription p = reference_plant();
  const DesignResult d = synthesize(p);
  const auto poly = cjob::design_float_poly(p, d, reference_members(), 50000);
  ASSERT_TRUE(poly.has_value());
  for (const FloatPolySlot& slot : poly->slots) EXPECT_LE(slot.exps.back(), 3);
}

}  // namespace
}  // namespace oneshot::design
