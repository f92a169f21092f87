/// @file c_job_filter.cpp
/// @brief The generated job's filter and control law: HalfKalman::update, correct(),
///        control_law(), quantize_input() and the converters, unrolled over the structure.
#include <cmath>
#include <cstdint>

#include "c_job/c_job_variant.hpp"

namespace oneshot::design::cjob {

Val VariantEmitter::cov(std::size_t i, std::size_t j) const {
  return ar().val(Qty::kCovariance, "s->p[" + std::to_string(upper_index(n_, i, j)) + "]");
}
Val VariantEmitter::state(std::size_t i) const { return ar().val(Qty::kState, "s->x[" + std::to_string(i) + "]"); }
Val VariantEmitter::input(std::size_t j) const { return ar().val(Qty::kInput, "s->u[" + std::to_string(j) + "]"); }

Val VariantEmitter::design_const(Qty q, const DenseMatrix& m, const PatternMask& pat, std::size_t i, std::size_t j,
                                 const std::string& what) const {
  if (pat.is_zero(i, j)) return Val::zero();
  if (pat.is_one(i, j)) return Val::one();
  return ar().constant(q, m(i, j), what + "[" + std::to_string(i) + "][" + std::to_string(j) + "]");
}

void VariantEmitter::emit_predict(CodeWriter& w) const {
  w.line("/* One-shot prediction over the interval of d (predict_state, predict_covariance with Q_d):");
  w.line("   x <- Phi x + Gamma u,  P <- Phi P Phi^T + Q_d. */");
  w.open("static void " + fn("predict") + "(" + state_type() + " *s, const " + triple_type() + " *d" + sat_param() +
         ") {");
  if (fixed()) w.line("(void)sat;");
  for (std::size_t i = 0; i < n_; ++i) {
    std::vector<Term> terms;
    for (std::size_t k = 0; k < n_; ++k) add_term(terms, false, phi("d", i, k), state(k));
    for (std::size_t k = 0; k < m_; ++k) add_term(terms, false, gamma("d", i, k), input(k));
    ar().accumulate(w, "const " + ar().ctype(Qty::kState) + " x" + std::to_string(i), Qty::kState, terms);
  }
  std::vector<std::vector<Val>> p(n_, std::vector<Val>(n_));
  for (std::size_t i = 0; i < n_; ++i)
    for (std::size_t j = 0; j < n_; ++j) p[i][j] = cov(i, j);
  emit_congruence(w, "d", p, "d", "p");
  for (std::size_t i = 0; i < n_; ++i) w.line("s->x[" + std::to_string(i) + "] = x" + std::to_string(i) + ";");
  for (std::size_t i = 0; i < n_; ++i)
    for (std::size_t j = i; j < n_; ++j)
      w.line("s->p[" + std::to_string(upper_index(n_, i, j)) + "] = p" + std::to_string(i) + std::to_string(j) + ";");
  w.close();
}

void VariantEmitter::emit_reciprocal(CodeWriter& w) const {
  const QFormat to = ar().fmt(Qty::kInverseCovariance);
  const QFormat from = ar().fmt(Qty::kCovariance);
  const int shift = to.frac + from.frac;
  if (shift < 0 || shift > 62) throw DesignError("C job: reciprocal formats need 0 <= F_to + F_from <= 62");
  const std::string max = to.bits == 16 ? "INT16_MAX" : "INT32_MAX";
  const std::string ret = to.bits == 16 ? "int16_t" : "int32_t";
  w.line("/* 1/v (reciprocal<>): v normalised to a 16-bit mantissa m 2^e (the core's loops of");
  w.line("   m = (m + 1) >> 1 give ceil(v / 2^e), taken here from the bit length), the exact quotient");
  w.line("   floor((2^31 + m/2) / m), then rescaled with rounding and saturation. */");
  w.open("static " + ret + " " + fn("reciprocal") + "(int32_t v, uint8_t *sat) {");
  w.line("uint32_t m, q;");
  w.line("int16_t e, shift;");
  w.open("if (v <= 0) {").line("*sat = 1u;").line("return " + max + ";").close();
  w.line("m = (uint32_t)v;");
  w.line("e = (int16_t)(os_bitlen(m) - 16);");
  w.open("if (e > 0) {")
      .line("m = (m + ((UINT32_C(1) << e) - 1u)) >> e;")
      .open("if (m >= UINT32_C(65536)) {")
      .line("++e;")
      .line("m = ((uint32_t)v + ((UINT32_C(1) << e) - 1u)) >> e;")
      .close()
      .middle("} else if (e < 0) {")
      .line("m <<= -e;")
      .close();
  w.line("q = os_div31(m);  /* in (2^15, 2^16] */");
  w.line("shift = (int16_t)(e - " + std::to_string(shift - 31) + ");");
  w.open("if (shift <= 0) {")
      .open("if (shift <= -16) {").line("*sat = 1u;").line("return " + max + ";").close()
      .line("q <<= -shift;")
      .middle("} else if (shift >= 18) {")
      .line("q = 0u;")
      .middle("} else {")
      .line("q = (q + (UINT32_C(1) << (shift - 1))) >> shift;")
      .close();
  w.open("if (q > (uint32_t)" + max + ") {").line("*sat = 1u;").line("return " + max + ";").close();
  w.line("return (" + ret + ")q;");
  w.close();
}

void VariantEmitter::emit_correct(CodeWriter& w) const {
  const PatternMask& cp = pat_.output;
  const std::string cov_t = ar().ctype(Qty::kCovariance);
  const std::string st_t = ar().ctype(Qty::kState);
  w.line("/* Measurement update (correct(), symmetric form, one output): S = C P C^T + R,");
  w.line("   K = P C^T / S, x += K (y - C x), P -= K (P C^T)^T. */");
  w.open("static uint8_t " + fn("correct") + "(" + state_type() + " *s, " + st_t + " y" + sat_param() + ") {");
  const auto c = [&](std::size_t j) { return design_const(Qty::kTransition, plant_.c, cp, 0, j, "C"); };
  for (std::size_t i = 0; i < n_; ++i) {
    std::vector<Term> terms;
    for (std::size_t k = 0; k < n_; ++k) add_term(terms, false, cov(i, k), c(k));
    ar().accumulate(w, "const " + cov_t + " pc" + std::to_string(i), Qty::kCovariance, terms);
  }
  {
    std::vector<Term> terms;
    for (std::size_t k = 0; k < n_; ++k) add_term(terms, false, c(k), ar().val(Qty::kCovariance, "pc" + std::to_string(k)));
    ar().accumulate(w, cov_t + " sv", Qty::kCovariance, terms);
  }
  const Val r = ar().constant(Qty::kCovariance, design_.r(0, 0), "R");
  const std::string inv_t = ar().ctype(Qty::kInverseCovariance);
  if (ar().q15()) {
    w.line("sv = os_q15_sat((int32_t)sv + " + r.expr + ", sat);");
    w.open("if (sv <= 0) {").line("return ONESHOT_JOB_STATUS_SINGULAR;").close();
    w.open("{").line("const " + inv_t + " inv = " + fn("reciprocal") + "(sv, sat);");
  } else if (fixed()) {
    w.line("sv = os_sat32((int64_t)sv + " + r.expr + ", sat);");
    w.open("if (sv <= 0) {").line("return ONESHOT_JOB_STATUS_SINGULAR;").close();
    w.open("{").line("const " + inv_t + " inv = " + fn("reciprocal") + "(sv, sat);");
  } else {
    w.line("sv = sv + " + r.expr + ";");
    w.open("if (!os_f32_positive(sv)) {  /* !(0 < sv) */").line("return ONESHOT_JOB_STATUS_SINGULAR;").close();
    w.open("{").line("const float inv = " + float_literal(1.0F) + " / sv;");
  }
  const Val inv = ar().val(Qty::kInverseCovariance, "inv");
  for (std::size_t i = 0; i < n_; ++i) {
    ar().mul(w, "const " + ar().ctype(Qty::kKalmanGain) + " k" + std::to_string(i), Qty::kKalmanGain,
             ar().val(Qty::kCovariance, "pc" + std::to_string(i)), inv);
  }
  {
    std::vector<Term> terms;
    add_value(terms, false, ar().val(Qty::kState, "y"));
    for (std::size_t j = 0; j < n_; ++j) add_term(terms, true, c(j), state(j));
    ar().accumulate(w, "const " + st_t + " innovation", Qty::kState, terms);
  }
  for (std::size_t i = 0; i < n_; ++i) {
    std::vector<Term> terms;
    add_value(terms, false, state(i));
    add_term(terms, false, ar().val(Qty::kKalmanGain, "k" + std::to_string(i)), ar().val(Qty::kState, "innovation"));
    ar().accumulate(w, "const " + st_t + " x" + std::to_string(i), Qty::kState, terms);
  }
  // float_poly, C a unit row e_c: P+_cj = P_cj - (P_cc/S) P_cj = P_cj R/S = K_j R (one product).
  std::size_t unit = n_;
  if (spec_.polynomial) {
    std::size_t ones = 0, zeros = 0;
    for (std::size_t k = 0; k < n_; ++k) {
      if (cp.is_one(0, k)) {
        unit = k;
        ++ones;
      } else if (cp.is_zero(0, k)) {
        ++zeros;
      }
    }
    if (ones != 1 || zeros + 1 != n_) unit = n_;
  }
  for (std::size_t i = 0; i < n_; ++i)
    for (std::size_t j = i; j < n_; ++j) {
      std::vector<Term> terms;
      if (i == unit || j == unit) {
        ar().mul(w, "const " + cov_t + " p" + std::to_string(i) + std::to_string(j), Qty::kCovariance,
                 ar().val(Qty::kKalmanGain, "k" + std::to_string(i == unit ? j : i)), r);
        continue;
      }
      add_value(terms, false, cov(i, j));
      add_term(terms, true, ar().val(Qty::kKalmanGain, "k" + std::to_string(i)),
               ar().val(Qty::kCovariance, "pc" + std::to_string(j)));
      ar().accumulate(w, "const " + cov_t + " p" + std::to_string(i) + std::to_string(j), Qty::kCovariance, terms);
    }
  for (std::size_t i = 0; i < n_; ++i) {
    w.line("s->k[" + std::to_string(i) + "] = k" + std::to_string(i) + ";");
    w.line("s->x[" + std::to_string(i) + "] = x" + std::to_string(i) + ";");
  }
  for (std::size_t i = 0; i < n_; ++i)
    for (std::size_t j = i; j < n_; ++j)
      w.line("s->p[" + std::to_string(upper_index(n_, i, j)) + "] = p" + std::to_string(i) + std::to_string(j) + ";");
  w.close();
  w.line("return ONESHOT_JOB_STATUS_OK;");
  w.close();
}

void VariantEmitter::emit_code_value(CodeWriter& w, const std::string& dest, Qty q, const std::string& what,
                                     double offset, double step, const std::string& code) const {
  // value_of_code: offset + code·step.
  std::vector<Term> terms;
  add_value(terms, false, ar().constant(q, offset, what + " offset"));
  add_term(terms, false, Val::code(code), ar().constant(Qty::kCodeStep, step, what + " step"));
  ar().accumulate(w, dest, q, terms);
}

void VariantEmitter::emit_quantize(CodeWriter& w, std::size_t j, const std::string& u, const std::string& code) const {
  const std::int32_t steps = design_.actuator_steps;
  const std::string n = int_literal(steps, 32);
  w.line("/* quantize_input: code = clamp(round((u - u_min) steps_per_volt), 0, " + std::to_string(steps) + "). */");
  if (!fixed()) {
    w.open("{").line("const float offset = " + u + " - " +
                     ar().constant(Qty::kInput, design_.u_min[j], "u_min").expr + ";");
    w.open("if (!os_f32_positive(offset)) {  /* !(0 < offset) */").line(code + " = 0;").middle("} else {");
    const float spv = static_cast<float>(design_.steps_per_volt[j]);
    w.line("const float steps = os_fmul(offset, " + ar().constant(Qty::kInverseInput, design_.steps_per_volt[j], "").expr + ");");
    if (spv > 0.0F && std::isfinite(spv)) {
      // offset > 0 and steps/volt > 0: steps is +0 … +inf, never NaN; on non-negative floats the
      // order of the values is the order of the bits, and steps + 1/2 < 2^23 truncates exactly.
      const float top = static_cast<float>(steps);
      w.open("if (!os_f32_below(steps, " + u32_literal(float_bits(top)) + ", " + float_literal(top) + ")) {")
          .line(code + " = " + n + ";");
      w.middle("} else {");
      w.line(code + " = os_f32_trunc(steps + " + float_literal(0.5F) + ");  /* (int32_t)(steps + 1/2), steps >= 0 */");
    } else {
      w.open("if (!(steps < " + float_literal(static_cast<float>(steps)) + ")) {").line(code + " = " + n + ";");
      w.middle("} else {");
      w.line(code + " = steps < " + float_literal(0.0F) + " ? -(int32_t)(-steps + " + float_literal(0.5F) +
             ") : (int32_t)(steps + " + float_literal(0.5F) + ");");
    }
    w.open("if (" + code + " > " + n + ") {").line(code + " = " + n + ";").close();
    w.close().close().close();
    return;
  }
  if (ar().q15()) {
    // offset = u - u_min in (0, 2^16) when positive, steps/volt in (0, 2^15): one unsigned
    // 32-bit product, rounded half up to a code.
    const Val umin = ar().constant(Qty::kInput, design_.u_min[j], "u_min");
    const Val spv = ar().constant(Qty::kInverseInput, design_.steps_per_volt[j], "PWM steps per volt");
    if (design_.steps_per_volt[j] <= 0) throw DesignError("C job q15: PWM steps per volt must be positive");
    const int shift = ar().fmt(Qty::kInput).frac + ar().fmt(Qty::kInverseInput).frac;
    if (shift < 1 || shift > 31) throw DesignError("C job q15: input and steps-per-volt formats too fine");
    w.open("{").line("const int32_t offset = (int32_t)" + u + " - (int32_t)" + umin.expr + ";");
    w.open("if (offset <= 0) {").line(code + " = 0;").middle("} else {");
    w.line("const uint32_t steps = ((uint32_t)offset * (uint32_t)" + spv.expr + " + " + u32_literal(1ULL << (shift - 1)) +
           ") >> " + std::to_string(shift) + ";");
    w.line(code + " = steps > (uint32_t)" + n + " ? " + n + " : (int32_t)steps;");
    w.close().close();
    return;
  }
  const QFormat sf = ar().fmt(Qty::kActuatorSteps);
  const Val umin = ar().constant(Qty::kInput, design_.u_min[j], "u_min");
  const Val spv = ar().constant(Qty::kInverseInput, design_.steps_per_volt[j], "PWM steps per volt");
  // ScalarTraits<Steps>::from_int(steps), evaluated by the core on every call.
  const double top = std::ldexp(static_cast<double>(steps), sf.frac);
  const double max = std::ldexp(1.0, sf.bits - 1) - 1;
  const bool from_int_saturates = top > max;
  const long long steps_raw = from_int_saturates ? static_cast<long long>(max) : static_cast<long long>(top);
  w.open("{").line("const int32_t offset = os_sat32((int64_t)" + u + " - " + umin.expr + ", sat);");
  w.open("if (offset <= 0) {").line(code + " = 0;").middle("} else {");
  ar().mul(w, "const int32_t steps", Qty::kActuatorSteps, ar().val(Qty::kInput, "offset"), spv);
  if (from_int_saturates) w.line("*sat = 1u;  /* from_int(steps) does not fit the steps format */");
  w.open("if (steps >= " + int_literal(steps_raw, sf.bits) + ") {").line(code + " = " + n + ";").middle("} else {");
  if (sf.frac <= 0) throw DesignError("C job: the actuator-steps format needs fractional bits");
  const std::string half = int_literal(std::int64_t{1} << (sf.frac - 1), 64);
  const bool spv_positive = design_.steps_per_volt[j] > 0;
  if (spv_positive && static_cast<double>(steps_raw) + std::ldexp(1.0, sf.frac - 1) < std::ldexp(1.0, 31)) {
    // offset > 0 and steps_per_volt > 0: steps ≥ 0, and steps < the top: a 32-bit rounding.
    w.line(code + " = (steps + " + int_literal(std::int64_t{1} << (sf.frac - 1), 32) + ") >> " +
           std::to_string(sf.frac) + ";");
  } else {
    w.line(code + " = steps >= 0 ? (int32_t)(((int64_t)steps + " + half + ") >> " + std::to_string(sf.frac) +
           ") : -(int32_t)((-(int64_t)steps + " + half + ") >> " + std::to_string(sf.frac) + ");");
  }
  w.open("if (" + code + " > " + n + ") {").line(code + " = " + n + ";").close();
  w.close().close().close();
}

void VariantEmitter::emit_init(CodeWriter& w) const {
  const bool scalar = m_ == 1;
  w.open("void oneshot_job_" + spec_.name + "_init(" + state_type() + " *s, " +
         (scalar ? "uint16_t pwm_code" : "const uint16_t pwm_code[" + std::to_string(m_) + "]") + ") {");
  if (fixed()) w.line("uint8_t *const sat = &s->saturated;");
  for (std::size_t i = 0; i < n_; ++i) {
    w.line("s->x[" + std::to_string(i) + "] = " + ar().zero(Qty::kState) + ";");
    w.line("s->k[" + std::to_string(i) + "] = " + ar().zero(Qty::kKalmanGain) + ";");
  }
  for (std::size_t i = 0; i < n_; ++i)
    for (std::size_t j = i; j < n_; ++j)
      w.line("s->p[" + std::to_string(upper_index(n_, i, j)) + "] = " +
             ar().constant(Qty::kCovariance, design_.p0(i, j), "P0").expr + ";");
  for (std::size_t j = 0; j < m_; ++j)
    emit_code_value(w, "s->u[" + std::to_string(j) + "]", Qty::kInput, "PWM", design_.u_min[j],
                    design_.volts_per_step[j], scalar ? "pwm_code" : "pwm_code[" + std::to_string(j) + "]");
  w.line("s->status = ONESHOT_JOB_STATUS_OK;");
  if (fixed()) w.line("s->saturated = 0u;");
  w.close();
}

void VariantEmitter::emit_run(CodeWriter& w) {
  const bool scalar = m_ == 1;
  const std::string st_t = ar().ctype(Qty::kState);
  const std::int32_t bound = tau_bound_us();
  const std::int32_t g = spec_.table.granularity_us;
  w.open(std::string(scalar ? "uint16_t" : "void") + " oneshot_job_" + spec_.name + "_run(" + state_type() +
         " *s, int32_t tau_us, uint16_t adc_code, uint16_t setpoint_code" +
         (scalar ? "" : ", uint16_t pwm_code[" + std::to_string(m_) + "]") + ") {");
  if (fixed()) w.line("uint8_t *const sat = &s->saturated;");
  if (!ar().q15()) w.line(triple_type() + " d;");
  w.line("uint8_t status, next;");
  for (std::size_t j = 0; j < m_; ++j) w.line("int32_t code" + std::to_string(j) + ";");
  w.line("/* The ADC and set-point codes in volts (output_of_code). */");
  emit_code_value(w, "const " + st_t + " y", Qty::kState, "ADC", design_.y_offset[0], design_.volts_per_code[0],
                  "adc_code");
  if (!spec_.polynomial)
    emit_code_value(w, "const " + st_t + " r", Qty::kState, "ADC", design_.y_offset[0], design_.volts_per_code[0],
                    "setpoint_code");
  w.line("/* Beyond +-" + std::to_string(bound) + " us every discretization below clamps exactly as at the bound,");
  w.line("   so bounding tau changes no result and keeps every integer in range. */");
  w.open("if (tau_us > " + int_literal(bound, 32) + ") {").line("tau_us = " + int_literal(bound, 32) + ";");
  w.middle("} else if (tau_us < " + int_literal(-bound, 32) + ") {").line("tau_us = " + int_literal(-bound, 32) + ";");
  w.close();
  if (!spec_.exact_subgrid) {
    w.line("/* SubGrid::kNearest: tau rounded to the grid once, ties away from zero on both sides of 0,");
    w.line("   so that h - tau stays on it (TableDiscretizer::quantize). */");
    w.open("if (tau_us > 0) {")
        .line("tau_us = " +
              divide_by_constant("tau_us + " + int_literal(g / 2, 32), static_cast<std::uint32_t>(g),
                                 static_cast<std::uint32_t>(bound + g / 2), divisions_) +
              " * " + int_literal(g, 32) + ";")
        .middle("} else if (tau_us < 0) {")
        .line("tau_us = -" +
              divide_by_constant("-tau_us + " + int_literal(g / 2, 32), static_cast<std::uint32_t>(g),
                                 static_cast<std::uint32_t>(bound + g / 2), divisions_) +
              " * " + int_literal(g, 32) + ";")
        .close();
  }
  const std::string h = int_literal(plant_.period_us, 32);
  w.line("/* Half Kalman (HalfKalman::update): predict to the sample, correct, predict to the actuation. */");
  if (ar().q15()) {
    w.line("status = " + fn("advance") + "(s, " + h + " - tau_us, sat);");
    w.line("next = " + fn("correct") + "(s, y, sat);");
    w.line("status = next > status ? next : status; /* worst_of: the codes rise with severity */");
    w.line("next = " + fn("advance") + "(s, tau_us, sat);");
    w.line("status = next > status ? next : status;");
  } else {
    w.line("status = " + fn("discretize") + "(" + h + " - tau_us, &d" + sat_arg() + ");");
    w.line(fn("predict") + "(s, &d" + sat_arg() + ");");
    w.line("next = " + fn("correct") + "(s, y" + sat_arg() + ");");
    w.line("status = next > status ? next : status; /* worst_of: the codes rise with severity */");
    w.line("next = " + fn("discretize") + "(tau_us, &d" + sat_arg() + ");");
    w.line("status = next > status ? next : status;");
    w.line(fn("predict") + "(s, &d" + sat_arg() + ");");
  }
  w.line("/* Control law u = N_u r - L (x - N_x r), actuator codes, and the input they realise. */");
  w.open("{");
  if (spec_.polynomial) {
    emit_float_poly_law(w);
    w.close();
    w.line("s->status = status;");
    if (scalar) w.line("return (uint16_t)code0;");
    if (!scalar)
      for (std::size_t j = 0; j < m_; ++j) w.line("pwm_code[" + std::to_string(j) + "] = (uint16_t)code" + std::to_string(j) + ";");
    w.close();
    return;
  }
  const auto& pat = pat_;
  for (std::size_t i = 0; i < n_; ++i) {
    std::vector<Term> terms;
    add_value(terms, false, state(i));
    add_term(terms, true, design_const(Qty::kFeedbackGain, design_.nx, pat.state_feedforward, i, 0, "Nx"),
             ar().val(Qty::kState, "r"));
    ar().accumulate(w, "const " + st_t + " err" + std::to_string(i), Qty::kState, terms);
  }
  for (std::size_t j = 0; j < m_; ++j) {
    std::vector<Term> terms;
    add_term(terms, false, design_const(Qty::kFeedbackGain, design_.nu, pat.input_feedforward, j, 0, "Nu"),
             ar().val(Qty::kState, "r"));
    for (std::size_t i = 0; i < n_; ++i)
      add_term(terms, true, design_const(Qty::kFeedbackGain, design_.l, pat.feedback, j, i, "L"),
               ar().val(Qty::kState, "err" + std::to_string(i)));
    ar().accumulate(w, "const " + ar().ctype(Qty::kInput) + " u" + std::to_string(j), Qty::kInput, terms);
  }
  for (std::size_t j = 0; j < m_; ++j) {
    emit_quantize(w, j, "u" + std::to_string(j), "code" + std::to_string(j));
    emit_code_value(w, "s->u[" + std::to_string(j) + "]", Qty::kInput, "PWM", design_.u_min[j],
                    design_.volts_per_step[j], "code" + std::to_string(j));
  }
  w.close();
  w.line("s->status = status;");
  if (scalar) {
    w.line("return (uint16_t)code0;");
  } else {
    for (std::size_t j = 0; j < m_; ++j) w.line("pwm_code[" + std::to_string(j) + "] = (uint16_t)code" + std::to_string(j) + ";");
  }
  w.close();
}

}  // namespace oneshot::design::cjob
