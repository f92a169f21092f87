/// @file c_arith.hpp
/// @brief The number formats of the generated C job: how each core operation (Accumulator,
///        mul, table slot conversion) is written in C, bit for bit like the C++ core.
///
/// Fixed point mirrors fixed_point.hpp: an accumulator sums exact products in a 64-bit
/// register with 16 guard bits, flooring terms finer than that, rounds once (ties upward)
/// and saturates. The generated code computes the same integers more cheaply where the
/// generator can prove it exact: products of 16-bit factors as one 16×16→32 multiply, a
/// 32×16 product as two, a common power of two factored out of exact terms (so the guard
/// bits cost no shifts), and a 32-bit register when the bound of the sum fits.
/// Float mirrors the floating Accumulator: left to right, the first term starting the sum.
#pragma once

#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "c_job/c_writer.hpp"
#include "oneshot/design/fixed_formats.hpp"

namespace oneshot::design::cjob {

/// The physical quantities of the job (as number_format.hpp names them).
enum class Qty {
  kTransition, kInputGain, kCovariance, kInverseCovariance, kState, kInput, kInverseInput,
  kActuatorSteps, kCodeStep, kKalmanGain, kFeedbackGain, kFraction
};

/// The format of quantity q in the design-step formats f.
QFormat format_of(const FixedFormats& f, Qty q);

/// An operand: structurally 0 or 1 (skipped or turned into a copy, as in the core's
/// structured kernels), or a C expression in a known format.
struct Val {
  enum class Kind { kZero, kOne, kExpr };
  Kind kind = Kind::kExpr;  ///< Structural zero / one, or data.
  std::string expr;         ///< C expression (kExpr).
  QFormat fmt;              ///< Fixed point: format of expr.
  bool count = false;       ///< An integer count in [0, 65535] (converter codes, Q31.0).

  /// Structural zero.
  static Val zero() { return Val{Kind::kZero, "", {}, false}; }
  /// Structural one.
  static Val one() { return Val{Kind::kOne, "", {}, false}; }
  /// Data in format f.
  static Val of(const std::string& e, QFormat f) { return Val{Kind::kExpr, e, f, false}; }
  /// A converter code in [0, 65535] (held in an int32 expression).
  static Val code(const std::string& e) { return Val{Kind::kExpr, e, QFormat{32, 0}, true}; }
  bool is_zero() const { return kind == Kind::kZero; }  ///< Structural zero.
  bool is_one() const { return kind == Kind::kOne; }    ///< Structural one.
};

/// Largest magnitude of a value's integer: 65535 for a converter count (unsigned 16 bits),
/// 2^(bits − 1) for a Q value.
inline double bound_of(const Val& v) { return v.count ? 65535.0 : std::ldexp(1.0, v.fmt.bits - 1); }

/// One accumulator term: ±x, ±a·b, or ±one() of the accumulator's format.
struct Term {
  enum class Kind { kValue, kProduct, kOne };
  Kind kind;      ///< What the term is.
  bool negative;  ///< Subtracted.
  Val a;          ///< The value, or the first factor.
  Val b;          ///< The second factor.
};

/// acc.add(x) / acc.sub(x).
void add_value(std::vector<Term>& terms, bool negative, const Val& x);
/// detail::accumulate_term: a·b honouring structural zeros and ones of both factors.
void add_term(std::vector<Term>& terms, bool negative, const Val& a, const Val& b);

/// How a number format is written in C.
class Arith {
 public:
  virtual ~Arith() = default;
  /// Fixed point (else float).
  virtual bool fixed() const = 0;
  /// The 16-bit format with 32-bit accumulators (q15_arith.hpp); implies fixed().
  virtual bool q15() const { return false; }
  /// C type holding quantity q.
  virtual std::string ctype(Qty q) const = 0;
  /// C type of q in the per-interval scratch (Φ, Γ, Q_d of one interval); ctype unless faster.
  virtual std::string scratch_ctype(Qty q) const { return ctype(q); }
  /// Format of q (fixed point).
  virtual QFormat fmt(Qty q) const = 0;
  /// Statements assigning dest = Accumulator<q> over `terms`, value().
  virtual void accumulate(CodeWriter& w, const std::string& dest, Qty out, const std::vector<Term>& terms) const = 0;
  /// Statement assigning dest = mul<to>(a, b).
  virtual void mul(CodeWriter& w, const std::string& dest, Qty to, const Val& a, const Val& b) const = 0;
  /// Design constant v stored as quantity q (`what` names it in errors).
  virtual Val constant(Qty q, double v, const std::string& what) const = 0;
  /// ScalarTraits<q>::one() as an expression; `saturates` when evaluating it raises the flag.
  virtual std::string one(Qty q, bool& saturates) const = 0;
  /// ScalarTraits<q>::zero().
  virtual std::string zero(Qty q) const = 0;
  /// TableStorage::to<q>(slot value raw·2^−frac) (fixed; raw has raw_bits) or the value (float).
  virtual std::string slot_to(Qty q, const std::string& raw, int frac, int raw_bits) const = 0;
  /// Value of a data operand of quantity q.
  Val val(Qty q, const std::string& expr) const { return Val::of(expr, fmt(q)); }
};

/// Integer arithmetic on a set of fixed-point formats (FixedArith, Q15Arith): the formats,
/// the constants and one() as raw literals of each quantity's format; saturations set `*sat`.
class IntegerArith : public Arith {
 public:
  explicit IntegerArith(FixedFormats f) : f_(std::move(f)) {}
  bool fixed() const override { return true; }
  QFormat fmt(Qty q) const override;
  Val constant(Qty q, double v, const std::string& what) const override;
  std::string one(Qty q, bool& saturates) const override;
  std::string zero(Qty) const override { return "0"; }
  /// ScalarTraits<Fixed<bits, frac>>::from_double(1.0) as a raw value.
  static long long one_raw(QFormat f, bool& saturates);

 private:
  FixedFormats f_;
};

/// The fixed-point formats the design step chose (16- and 32-bit).
class FixedArith final : public IntegerArith {
 public:
  using IntegerArith::IntegerArith;
  std::string ctype(Qty q) const override { return fmt(q).bits == 16 ? "int16_t" : "int32_t"; }
  void accumulate(CodeWriter& w, const std::string& dest, Qty out, const std::vector<Term>& terms) const override;
  void mul(CodeWriter& w, const std::string& dest, Qty to, const Val& a, const Val& b) const override;
  std::string slot_to(Qty q, const std::string& raw, int frac, int raw_bits) const override;
  /// Helper functions the fixed code calls (emitted once per file).
  static void emit_helpers(CodeWriter& w);
  /// The division-free exact quotient and bit length used by the reciprocal (emitted once).
  static void emit_division_helpers(CodeWriter& w);
};

/// IEEE single precision throughout (the firmware's float format).
class FloatArith final : public Arith {
 public:
  bool fixed() const override { return false; }
  std::string ctype(Qty) const override { return "float"; }
  QFormat fmt(Qty) const override { return QFormat{32, 0}; }
  void accumulate(CodeWriter& w, const std::string& dest, Qty out, const std::vector<Term>& terms) const override;
  void mul(CodeWriter& w, const std::string& dest, Qty to, const Val& a, const Val& b) const override;
  Val constant(Qty q, double v, const std::string& what) const override;
  std::string one(Qty, bool& saturates) const override {
    saturates = false;
    return float_literal(1.0F);
  }
  std::string zero(Qty) const override { return float_literal(0.0F); }
  std::string slot_to(Qty, const std::string& raw, int, int) const override { return raw; }
  /// The comparisons, exact conversions and multiply the float code calls (os_f32_*, os_fmul):
  /// integer forms under ONESHOT_JOB_INTEGER_FLOAT (default on a Cortex-M0), plain C otherwise.
  static void emit_helpers(CodeWriter& w);

 private:
  /// The correctly rounded integer multiply os_fmul (inside the ONESHOT_JOB_INTEGER_FLOAT block).
  static void emit_fmul(CodeWriter& w);
};

}  // namespace oneshot::design::cjob
