/// @file q15_arith.hpp
/// @brief The 16-bit number format of the generated C job (variants q15_*): every stored
///        value (estimate, covariance, input, Φ, Γ, Q_d, gains) in 16 bits with a binary
///        point chosen per quantity at design time, every product 16×16→32, every sum in a
///        32-bit accumulator — a dsPIC33's MAC format, and no 64-bit arithmetic anywhere.
///
/// Rounding and saturation (defined, unit-tested in c_job_q15_test):
///   sum   s = Σ t_i·2^(B−f_i)   terms at fraction f_i brought to the accumulator fraction B:
///                               exact (multiplied) when f_i ≤ B, floored (>>) when f_i > B;
///                               B is the largest fraction ≤ max f_i whose worst-case sum
///                               (every operand at its format's bound) stays below 2^31,
///                               so no 32-bit sum can overflow (proved at generation time)
///   value v = (s + 2^(r−1)) >> r,  r = B − F_out   round half up
///   store sat16(v)              clamp to [−2^15, 2^15−1], raising the sticky flag; a plain
///                               cast when the bound proves |v| < 2^15
/// Not bit-identical to any C++ core format: its oracle is the generated C itself (host gcc,
/// avr-gcc/simavr, both Cortex-M images) and a double-precision reference with a measured
/// tolerance.
#pragma once

#include <string>
#include <vector>

#include "c_job/c_arith.hpp"

namespace oneshot::design::cjob {

/// The 16-bit formats of the q15 variants, from the fixed-point design's ranges: states and
/// inputs hold 2× the converter ranges, covariances 2× max(P0, P, R, Q, Q_d) (not 256×: a
/// saturation is defined and flagged), 1/S up to 1/min(R), the code steps and PWM steps per
/// volt exactly their constants; Φ, Γ, gains and the sub-grid fraction as the fixed design.
FixedFormats q15_formats(const FixedFormats& fixed);

/// 16-bit storage, 32-bit accumulation (see the file comment).
class Q15Arith final : public IntegerArith {
 public:
  using IntegerArith::IntegerArith;
  bool q15() const override { return true; }
  std::string ctype(Qty) const override { return "int16_t"; }
  /// 16-bit values in a register-width int where that is faster (32-bit cores).
  std::string scratch_ctype(Qty) const override { return "int_fast16_t"; }
  void accumulate(CodeWriter& w, const std::string& dest, Qty out, const std::vector<Term>& terms) const override;
  void mul(CodeWriter& w, const std::string& dest, Qty to, const Val& a, const Val& b) const override;
  std::string slot_to(Qty q, const std::string& raw, int frac, int raw_bits) const override;
};

}  // namespace oneshot::design::cjob
