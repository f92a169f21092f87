/// @file c_job_api.cpp
/// @brief A variant's public C declarations and the order of its definitions.
#include <cctype>

#include "c_job/c_job_variant.hpp"

namespace oneshot::design::cjob {

namespace {
std::string upper(const std::string& s) {
  std::string o;
  for (char c : s) o += static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return o;
}
}  // namespace

void VariantEmitter::header(CodeWriter& w) const {
  const std::string up = "ONESHOT_JOB_" + upper(spec_.name);
  const std::string name = "oneshot_job_" + spec_.name;
  const bool scalar = m_ == 1;
  std::string states;
  for (std::size_t i = 0; i < n_; ++i) states += (i ? ", " : "") + comment_text(plant_.states[i]);
  w.line("/* ---- " + spec_.name + ": " + (ar().q15() ? "16-bit Q formats, 32-bit accumulators" : fixed() ? "fixed point" : "IEEE single precision") + ", " +
         (spec_.polynomial      ? "Phi, Gamma, Q_d as one polynomial in tau per entry (own arithmetic)"
          : spec_.exact_subgrid ? "exact between grid points (table + residual polynomial)"
                                : "tau rounded to the nearest grid point") +
         " ---- */");
  w.line("#ifndef ONESHOT_JOB_WITHOUT_" + upper(spec_.name));
  w.line("");
  w.line("/** This variant is in the generated files. */");
  w.line("#define ONESHOT_JOB_HAS_" + upper(spec_.name) + " 1");
  if (fixed()) {
    const auto frac = [&](Qty q) { return std::to_string(ar().fmt(q).frac); };
    w.line("/** Fractional bits of the estimate and the input: value = raw * 2^-bits (volts). */");
    w.line("#define " + up + "_STATE_FRAC_BITS " + frac(Qty::kState));
    w.line("/** Fractional bits of the input s->u (volts). */");
    w.line("#define " + up + "_INPUT_FRAC_BITS " + frac(Qty::kInput));
    w.line("/** Fractional bits of the covariance entries (volts squared). */");
    w.line("#define " + up + "_COVARIANCE_FRAC_BITS " + frac(Qty::kCovariance));
    w.line("/** Fractional bits of 1/S, the inverse innovation variance. */");
    w.line("#define " + up + "_INVERSE_COVARIANCE_FRAC_BITS " + frac(Qty::kInverseCovariance));
    w.line("/** Fractional bits of the Kalman gain. */");
    w.line("#define " + up + "_GAIN_FRAC_BITS " + frac(Qty::kKalmanGain));
    w.line("");
  }
  const std::string st = ar().ctype(Qty::kState);
  w.line("/** Everything the job keeps between runs (allocate one; no heap). Read-only for the caller");
  w.line("    except `" + std::string(fixed() ? "saturated" : "status") + "`, which it may clear. */");
  w.open("typedef struct {");
  w.line(st + " x[" + std::to_string(n_) + "];  /**< Estimate at the next actuation instant (" + states + "). */");
  w.line(ar().ctype(Qty::kCovariance) + " p[" + std::to_string(n_ * (n_ + 1) / 2) +
         "];  /**< Its covariance, upper triangle row by row. */");
  w.line(ar().ctype(Qty::kInput) + " u[" + std::to_string(m_) +
         "];  /**< Input the last PWM code realises (volts). */");
  w.line(ar().ctype(Qty::kKalmanGain) + " k[" + std::to_string(n_) + "];  /**< Kalman gain of the last correction. */");
  w.line("uint8_t status;  /**< ONESHOT_JOB_STATUS_* of the last run. */");
  if (fixed()) w.line("uint8_t saturated;  /**< Sticky: an operation saturated since init (clear it to re-arm). */");
  w.close("} " + state_type() + ";");
  w.line("");
  w.line("/** Starts the filter at the steady-state prior: estimate 0, covariance P0, and the input that");
  w.line("    `pwm_code` realises (the duty the actuation timer holds before the first job). */");
  w.line("void " + name + "_init(" + state_type() + " *s, " +
         (scalar ? "uint16_t pwm_code" : "const uint16_t pwm_code[" + std::to_string(m_) + "]") + ");");
  w.line("/** One control job: `adc_code` sampled `tau_us` microseconds before the next actuation");
  w.line("    instant, set-point `setpoint_code` (in ADC codes). Returns the PWM code to write at that");
  w.line("    instant, 0.." + std::to_string(design_.actuator_steps) + "; afterwards s->x is the estimate there. */");
  w.line(std::string(scalar ? "uint16_t " : "void ") + name + "_run(" + state_type() +
         " *s, int32_t tau_us, uint16_t adc_code, uint16_t setpoint_code" +
         (scalar ? "" : ", uint16_t pwm_code[" + std::to_string(m_) + "]") + ");");
  w.line("/** Entry i of the estimate at the next actuation instant (" +
         std::string(fixed() ? "raw, see _STATE_FRAC_BITS" : "volts") + "); 0 for i out of range. */");
  w.line(st + " " + name + "_estimate(const " + state_type() + " *s, uint8_t i);");
  w.line("");
  w.line("#endif");
  w.line("");
}

void VariantEmitter::source(CodeWriter& w) {
  w.line("/* ======== " + spec_.name + " ======== */");
  w.line("#ifndef ONESHOT_JOB_WITHOUT_" + upper(spec_.name));
  w.line("");
  if (spec_.polynomial) {
    emit_triple(w);
    emit_float_poly(w);
    emit_predict(w);
  } else if (ar().q15()) {
    emit_triple(w);
    emit_q15_table(w);
    emit_q15_interval(w);
    emit_predict(w);
    emit_q15_advance(w);
  } else {
    emit_table(w);
    emit_triple(w);
    emit_load(w);
    if (spec_.exact_subgrid) emit_residual(w);
    if (!grid()) emit_identity(w);  // grid point 0 is the identity
    emit_compose(w);
    emit_in_range(w);
    emit_discretize(w);
    emit_predict(w);
  }
  if (ar().q15()) {
    emit_q15_reciprocal(w);
  } else if (fixed()) {
    emit_reciprocal(w);
  }
  emit_correct(w);
  emit_init(w);
  emit_run(w);
  w.open(ar().ctype(Qty::kState) + " oneshot_job_" + spec_.name + "_estimate(const " + state_type() +
         " *s, uint8_t i) {");
  w.line("return i < " + std::to_string(n_) + "u ? s->x[i] : " + ar().zero(Qty::kState) + ";");
  w.close();
  w.line("");
  w.line("#endif");
  w.line("");
}

}  // namespace oneshot::design::cjob
