/// @file c_job_q15_test.cpp
/// @brief The q15 number format of the generated C job: its formats, the 32-bit accumulation (no overflow possible, floor/round/saturate as
///        documented) and the generated q15 code (no 64-bit, no division, no 32x32 product).
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "c_job/q15_arith.hpp"
#include "oneshot/design/c_job_emitter.hpp"
#include "oneshot/design/fixed_formats.hpp"
#include "oneshot/design/structure_analysis.hpp"
#include "oneshot/design/table_builder.hpp"
#include "support/test_plants.hpp"

namespace oneshot::design {
namespace {

using cjob::CodeWriter;
using cjob::Q15Arith;
using cjob::Qty;
using cjob::Term;
using cjob::Val;

TEST(CJobQ15, FormatsAreSixteenBitAndHoldTheirRanges) {
  const PlantDescription p = reference_plant();
  const DesignResult d = synthesize(p);
  const FixedFormats f = cjob::q15_formats(choose_fixed_formats(p, d));
  for (const QFormat q : {f.state, f.input, f.covariance, f.inverse_covariance, f.code_step, f.inverse_input,
                          f.transition, f.input_gain, f.kalman_gain, f.feedback_gain, f.fraction})
    EXPECT_EQ(q.bits, 16);
  for (const QuantityFormat& q : f.table) {
    EXPECT_EQ(q.format.bits, 16) << q.name;
    EXPECT_GE(q.format.max_value(), q.range) << q.name;
  }
  EXPECT_EQ(f.state.frac, 13);  // ±4 V, 0.12 mV: finer than the 0.8 mV ADC step
  for (std::size_t i = 0; i < p.n(); ++i)
    for (std::size_t j = 0; j < p.n(); ++j) EXPECT_LE(std::fabs(d.p0(i, j)), f.covariance.max_value());
}

class Q15Sum : public ::testing::Test {
 protected:
  Q15Sum() {
    f.state = {16, 13};
    f.transition = {16, 13};
    f.input_gain = {16, 14};
    f.input = {16, 13};
    f.covariance = {16, 27};
  }
  std::string sum(Qty out, const std::vector<Term>& terms) const {
    CodeWriter w;
    Q15Arith(f).accumulate(w, "x", out, terms);
    return w.str();
  }
  FixedFormats f;
};

TEST_F(Q15Sum, WorstCaseSumsFloorTheirTermsIntoThirtyTwoBits) {
  const Q15Arith a(f);
  std::vector<Term> t;
  cjob::add_value(t, false, a.val(Qty::kState, "x0"));
  cjob::add_term(t, false, a.val(Qty::kTransition, "phi"), a.val(Qty::kState, "x1"));
  cjob::add_term(t, false, a.val(Qty::kInputGain, "gam"), a.val(Qty::kInput, "u"));
  const std::string s = sum(Qty::kState, t);
  // x0 2^13 + phi x1 (Q26, < 2^30) + gam u (Q27, < 2^30, floored to Q26): the worst case
  // reaches 2^31 at Q27, so the accumulator works at Q26, one bit dropped (floor) from gam u.
  EXPECT_NE(s.find("(int32_t)os_q15_m(phi, x1) +"), std::string::npos) << s;
  EXPECT_NE(s.find("((int32_t)os_q15_m(gam, u) >> 1)"), std::string::npos) << s;
  EXPECT_NE(s.find("os_q15_sat("), std::string::npos) << s;       // may leave 16 bits: saturated
  EXPECT_NE(s.find("((int32_t)x0 * 2 + 1) * 4096"), std::string::npos) << s;  // x0 2^13 + 2^12: half up
  EXPECT_NE(s.find(">> 13"), std::string::npos) << s;
  EXPECT_EQ(s.find("int64"), std::string::npos) << s;
}

TEST_F(Q15Sum, SumsThatCannotOverflowAreCastNotSaturated) {
  std::vector<Term> t;
  const Val small = Val::of("v", QFormat{16, 15});
  cjob::add_term(t, false, small, Val::of("w", QFormat{16, 15}));  // |v w| <= 1: Q13 holds it
  const std::string s = sum(Qty::kState, t);
  EXPECT_NE(s.find("(int16_t)("), std::string::npos) << s;
  EXPECT_EQ(s.find("os_sat16"), std::string::npos) << s;
}

TEST_F(Q15Sum, ACopyStaysACopy) {
  const Q15Arith a(f);
  std::vector<Term> t;
  cjob::add_value(t, false, a.val(Qty::kCovariance, "p0"));
  EXPECT_EQ(sum(Qty::kCovariance, t), "x = p0;\n");
}

TEST(CJobQ15, GeneratedJobIsSixteenBitWithoutDivisionOrWideProducts) {
  const PlantDescription p = reference_plant();
  const DesignResult d = synthesize(p);
  const PlantPatterns pat = analyse_structure(p, d);
  const FixedFormats f = choose_fixed_formats(p, d);
  const auto tf = build_table<float>(p, d, pat);
  const auto tq = build_table<BlockFixedStorage>(p, d, pat);
  const CJobSources c = emit_c_job(p, d, pat, tf, &f, &tq, "c_job_q15_test");
  ASSERT_NE(std::find(c.variants.begin(), c.variants.end(), "q15_table"), c.variants.end());
  ASSERT_NE(std::find(c.variants.begin(), c.variants.end(), "q15_nearest"), c.variants.end());
  const std::size_t from = c.source.find("/* ======== q15_table ======== */");
  ASSERT_NE(from, std::string::npos);
  const std::size_t to = c.source.find("/* ======== float_table", from);
  std::string q15 = c.source.substr(from, to == std::string::npos ? std::string::npos : to - from);
  for (std::size_t a = q15.find("/*"); a != std::string::npos; a = q15.find("/*", a)) q15.erase(a, q15.find("*/", a) + 2 - a);
  for (const char* banned : {"int64_t", "INT64_C", "os_m32", "os_sat32", "float", " / "})
    EXPECT_EQ(q15.find(banned), std::string::npos) << banned;
  EXPECT_NE(c.header.find("int16_t x[2]"), std::string::npos);  // estimate and covariance in 16 bits
  EXPECT_NE(c.header.find("int16_t p[3]"), std::string::npos);
}

}  // namespace
}  // namespace oneshot::design
