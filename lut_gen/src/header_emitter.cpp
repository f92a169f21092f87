/// @file header_emitter.cpp
/// @brief Generated header text (see header_emitter.hpp).
#include "oneshot/design/header_emitter.hpp"

#include "oneshot/design/cpp_text.hpp"

#include <cctype>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <vector>

namespace oneshot::design {
namespace {

std::string literal(float v) {
  char buf[48];
  std::snprintf(buf, sizeof buf, "%aF", static_cast<double>(v));
  return buf;
}

std::string literal(double v) {
  char buf[48];
  std::snprintf(buf, sizeof buf, "%a", v);
  return buf;
}

template <typename T>
std::string int_list(const std::vector<T>& v) {
  std::ostringstream o;
  for (std::size_t i = 0; i < v.size(); ++i) o << (i ? ", " : "") << static_cast<long long>(v[i]);
  return o.str();
}

template <typename S>
std::string value_list(const std::vector<S>& v, std::size_t per_line) {
  std::ostringstream o;
  for (std::size_t i = 0; i < v.size(); ++i) {
    if (i) o << (per_line && i % per_line == 0 ? ",\n      " : ", ");
    o << literal(v[i]);
  }
  return o.str();
}

template <typename S>
std::string matrix(const char* scalar, const DenseMatrix& m) {
  std::vector<S> values;
  for (double x : m.values) values.push_back(static_cast<S>(x));
  std::ostringstream o;
  o << "::oneshot::Matrix<" << scalar << ", " << m.rows << ", " << m.cols << ">{{" << value_list(values, 0) << "}}";
  return o.str();
}

template <typename S>
std::string vec(const char* scalar, const std::vector<double>& v) {
  DenseMatrix m{v.size(), 1, v};
  return matrix<S>(scalar, m);
}

/// A continuous-time matrix per second rescaled to per microsecond (times `extra`).
DenseMatrix per_us(DenseMatrix m, double extra = 1.0) {
  for (double& x : m.values) x *= 1e-6 * extra;
  return m;
}

/// The table layout shared by every number format: level radices, slot maps, entry times.
template <typename Storage>
void emit_layout(std::ostringstream& o, const TableData<Storage>& t) {
  const char* slot_t = t.narrow_slots() ? "std::int8_t" : "std::int16_t";
  o << "  static constexpr std::uint16_t kRadix[] = {" << int_list(t.radix) << "};\n"
    << "  static constexpr std::uint16_t kLevelOffset[] = {" << int_list(t.level_offset) << "};\n"
    << "  static constexpr " << slot_t << " kPhiSlot[] = {" << int_list(t.phi_slot) << "};\n"
    << "  static constexpr " << slot_t << " kGammaSlot[] = {" << int_list(t.gamma_slot) << "};\n"
    << "  static constexpr " << slot_t << " kQdSlot[] = {" << int_list(t.qd_slot) << "};\n"
    << "  static constexpr " << (t.narrow_slots() ? "std::uint8_t" : "std::uint16_t") << " kResidualOffset[] = {"
    << int_list(t.residual_offset) << "};\n"
    << "  /// Entry times (us): " << int_list(t.entry_time_us) << ".\n";
}

template <typename S>
void emit_constants(std::ostringstream& o, const char* scalar, const PlantDescription& plant, const DesignResult& d,
                    const TableData<S>& t) {
  const std::size_t n = plant.n();
  const std::size_t m = plant.m();
  const std::size_t p = plant.p();
  const DenseMatrix a_us = per_us(plant.a);
  const DenseMatrix b_us = per_us(plant.b);
  const DenseMatrix qc_us = per_us(d.qc);
  o << "/// Constants in " << scalar << ".\n"
    << "template <>\nstruct PlantConstants<" << scalar << "> {\n"
    << "  /// Number formats of every quantity.\n"
    << "  using Format = ::oneshot::UniformFormat<" << scalar << ">;\n";
  emit_layout(o, t);
  o << "  static constexpr " << scalar << " kValues[] = {\n      " << value_list(t.values, t.slots) << "};\n"
    << "  static constexpr std::uint8_t kResidualLow[] = {" << int_list(t.residual_low) << "};\n"
    << "  static constexpr std::uint8_t kResidualHigh[] = {" << int_list(t.residual_high) << "};\n"
    << "  static constexpr " << scalar << " kResidualCoefficients[] = {" << value_list(t.residual_coefficients, 0)
    << "};\n"
    << "  /// The look-up table (" << t.bytes() << " bytes).\n"
    << "  static constexpr ::oneshot::TableView<" << scalar << ", " << (t.narrow_slots() ? "std::int8_t" : "std::int16_t")
    << "> kTable{" << t.granularity_us << ", " << t.range_us
    << ", " << t.radix.size() << ", kRadix, kLevelOffset, " << t.entry_time_us.size() << ", "
    << static_cast<int>(t.slots) << ", " << static_cast<int>(t.transition_slots)
    << ", kPhiSlot, kGammaSlot, kQdSlot, kValues, kResidualLow, kResidualHigh, kResidualOffset, "
    << t.residual_coefficients.size() << ", kResidualCoefficients, nullptr, nullptr};\n"
    << "  /// Continuous model per microsecond, for the generic routine.\n"
    << "  static constexpr ::oneshot::ContinuousModelPerUs<" << scalar << ", " << n << ", " << m << "> kModel{\n"
    << "      " << matrix<S>(scalar, a_us) << ",\n      " << matrix<S>(scalar, b_us) << ",\n      "
    << matrix<S>(scalar, qc_us) << "};\n"
    << "  /// Design results (u = -L x).\n"
    << "  static constexpr ::oneshot::ControllerDesign<Format, " << n << ", " << m << ", " << p << "> kDesign{\n"
    << "      " << plant.period_us << ",  // period_us\n"
    << "      " << matrix<S>(scalar, plant.c) << ",  // C\n"
    << "      " << matrix<S>(scalar, d.l) << ",  // L\n"
    << "      " << matrix<S>(scalar, d.nx) << ",  // N_x\n"
    << "      " << matrix<S>(scalar, d.nu) << ",  // N_u\n"
    << "      " << matrix<S>(scalar, d.q_constant) << ",  // Q (constant)\n"
    << "      " << matrix<S>(scalar, d.r) << ",  // R\n"
    << "      " << matrix<S>(scalar, d.p0) << ",  // P0\n"
    << "      " << matrix<S>(scalar, d.phi_h) << ",  // Phi(h)\n"
    << "      " << matrix<S>(scalar, d.gamma_h) << ",  // Gamma(h)\n"
    << "      " << matrix<S>(scalar, d.qd_h) << ",  // Qd(h)\n"
    << "      " << matrix<S>(scalar, d.deadbeat_gain) << ",  // K deadbeat\n"
    << "      {" << vec<S>(scalar, d.u_min) << ", " << vec<S>(scalar, d.volts_per_step) << ", "
    << vec<S>(scalar, d.steps_per_volt) << ", " << d.actuator_steps << "},  // actuator\n"
    << "      {" << vec<S>(scalar, d.y_offset) << ", " << vec<S>(scalar, d.volts_per_code) << "}};  // sensor\n"
    << "};\n"
    << "static_assert(::oneshot::TableDiscretizer<PlantConstants<" << scalar << ">::Format, PlantStructure, " << scalar
    << ">::maps_match_structure(PlantConstants<" << scalar << ">::kTable),\n"
    << "              \"table slot maps disagree with the structure\");\n\n";
}

/// Fixed constants: matrices of raw mantissas of a named format.
struct FixedEmitter {
  const FixedFormats& f;

  std::string matrix(const std::string& type, const QFormat& q, const DenseMatrix& m, const std::string& what) const {
    std::ostringstream o;
    o << "::oneshot::Matrix<FixedFormat::" << type << ", " << m.rows << ", " << m.cols << ">{{";
    for (std::size_t k = 0; k < m.values.size(); ++k) {
      std::ostringstream name;
      name << what << "[" << k / m.cols << "][" << k % m.cols << "]";
      o << (k ? ", " : "") << "::oneshot::fixed_raw<FixedFormat::" << type << ">(" << q.raw_of(m.values[k], name.str())
        << ")";
    }
    o << "}}";
    return o.str();
  }
  std::string vec(const std::string& type, const QFormat& q, const std::vector<double>& v, const std::string& what) const {
    return matrix(type, q, DenseMatrix{v.size(), 1, v}, what);
  }
};

void emit_fixed(std::ostringstream& o, const PlantDescription& plant, const DesignResult& d, const FixedFormats& f,
                const TableData<BlockFixedStorage>& t) {
  const std::size_t n = plant.n();
  const std::size_t m = plant.m();
  const std::size_t p = plant.p();
  // snake_case quantity name -> PascalCase type name (constant_name without its 'k')
  const auto type_of = [](const std::string& name) { return constant_name(name).substr(1); };
  o << "/// Fixed-point formats chosen by the design step from the plant's numbers.\n"
    << "struct FixedFormat {\n";
  for (const QuantityFormat& q : f.table) {
    o << "  using " << type_of(q.name) << " = " << q.format.cpp_type() << ";  ///< |value| <= " << q.range << ": "
      << q.rationale << "\n";
  }
  o << "  /// Van Loan runs on Q_c * 2^kQdScaleShift.\n"
    << "  static constexpr int kQdScaleShift = " << f.qd_scale_shift << ";\n"
    << "};\n";
  for (const QuantityFormat& q : f.table) {
    o << "static_assert(FixedFormat::" << type_of(q.name) << "::max_value() >= " << literal(q.range)
      << ", \"" << q.name << " format narrower than its range\");\n";
  }
  o << "\n/// Tag selecting the fixed-point constants.\nstruct FixedTag {};\n\n";
  const FixedEmitter e{f};
  const DenseMatrix a_us = per_us(plant.a);
  const DenseMatrix b_us = per_us(plant.b);
  const DenseMatrix qc_us = per_us(d.qc, std::ldexp(1.0, f.qd_scale_shift));
  std::vector<std::string> values;
  for (const Mantissa16& v : t.values) values.push_back("{" + std::to_string(v.raw) + "}");
  std::vector<std::string> coeffs;
  for (const Mantissa32& c : t.residual_coefficients) coeffs.push_back("{" + std::to_string(c.raw) + "}");
  const auto join = [](const std::vector<std::string>& v, std::size_t per_line) {
    std::ostringstream s;
    for (std::size_t i = 0; i < v.size(); ++i) s << (i ? (per_line && i % per_line == 0 ? ",\n      " : ", ") : "") << v[i];
    return s.str();
  };
  o << "/// Constants in the fixed-point formats.\n"
    << "template <>\nstruct PlantConstants<FixedTag> {\n"
    << "  /// Number formats of every quantity.\n"
    << "  using Format = FixedFormat;\n";
  emit_layout(o, t);
  o << "  static constexpr ::oneshot::Mantissa16 kValues[] = {\n      " << join(values, t.slots) << "};\n"
    << "  static constexpr std::int8_t kValueFrac[] = {" << int_list(t.value_frac) << "};\n"
    << "  static constexpr std::uint8_t kResidualLow[] = {" << int_list(t.residual_low) << "};\n"
    << "  static constexpr std::uint8_t kResidualHigh[] = {" << int_list(t.residual_high) << "};\n"
    << "  static constexpr ::oneshot::Mantissa32 kResidualCoefficients[] = {" << join(coeffs, 0) << "};\n"
    << "  static constexpr std::int8_t kResidualFrac[] = {" << int_list(t.residual_frac) << "};\n"
    << "  /// The look-up table (" << t.bytes() << " bytes, 16-bit mantissas with a scale per slot).\n"
    << "  static constexpr ::oneshot::TableView<::oneshot::BlockFixedStorage, "
    << (t.narrow_slots() ? "std::int8_t" : "std::int16_t") << "> kTable{" << t.granularity_us << ", "
    << t.range_us << ", " << t.radix.size() << ", kRadix, kLevelOffset, " << t.entry_time_us.size() << ", "
    << static_cast<int>(t.slots) << ", " << static_cast<int>(t.transition_slots)
    << ", kPhiSlot, kGammaSlot, kQdSlot, kValues, kResidualLow, kResidualHigh, kResidualOffset, "
    << t.residual_coefficients.size() << ", kResidualCoefficients, kValueFrac, kResidualFrac};\n"
    << "  /// Continuous model per microsecond (Q_c scaled by 2^kQdScaleShift), for the generic routine.\n"
    << "  static constexpr ::oneshot::ContinuousModelPerUs<FixedFormat::Compute, " << n << ", " << m
    << ", FixedFormat::ModelA, FixedFormat::ModelB, FixedFormat::ModelQc> kModel{\n"
    << "      " << e.matrix("ModelA", f.model_a, a_us, "A per us") << ",\n      "
    << e.matrix("ModelB", f.model_b, b_us, "B per us") << ",\n      "
    << e.matrix("ModelQc", f.model_qc, qc_us, "Qc per us") << "};\n"
    << "  /// Design results (u = -L x).\n"
    << "  static constexpr ::oneshot::ControllerDesign<Format, " << n << ", " << m << ", " << p << "> kDesign{\n"
    << "      " << plant.period_us << ",  // period_us\n"
    << "      " << e.matrix("Transition", f.transition, plant.c, "C") << ",\n"
    << "      " << e.matrix("FeedbackGain", f.feedback_gain, d.l, "L") << ",\n"
    << "      " << e.matrix("FeedbackGain", f.feedback_gain, d.nx, "Nx") << ",\n"
    << "      " << e.matrix("FeedbackGain", f.feedback_gain, d.nu, "Nu") << ",\n"
    << "      " << e.matrix("Covariance", f.covariance, d.q_constant, "Q") << ",\n"
    << "      " << e.matrix("Covariance", f.covariance, d.r, "R") << ",\n"
    << "      " << e.matrix("Covariance", f.covariance, d.p0, "P0") << ",\n"
    << "      " << e.matrix("Transition", f.transition, d.phi_h, "Phi(h)") << ",\n"
    << "      " << e.matrix("InputGain", f.input_gain, d.gamma_h, "Gamma(h)") << ",\n"
    << "      " << e.matrix("Covariance", f.covariance, d.qd_h, "Qd(h)") << ",\n"
    << "      " << e.matrix("KalmanGain", f.kalman_gain, d.deadbeat_gain, "K deadbeat") << ",\n"
    << "      {" << e.vec("Input", f.input, d.u_min, "u_min") << ", " << e.vec("CodeStep", f.code_step, d.volts_per_step, "volts per PWM step")
    << ", " << e.vec("InverseInput", f.inverse_input, d.steps_per_volt, "PWM steps per volt") << ", " << d.actuator_steps << "},\n"
    << "      {" << e.vec("State", f.state, d.y_offset, "ADC offset") << ", " << e.vec("CodeStep", f.code_step, d.volts_per_code, "ADC LSB")
    << "}};\n"
    << "};\n"
    << "static_assert(::oneshot::TableDiscretizer<FixedFormat, PlantStructure, ::oneshot::BlockFixedStorage>::maps_match_structure(\n"
    << "                  PlantConstants<FixedTag>::kTable),\n"
    << "              \"table slot maps disagree with the structure\");\n\n";
}

void emit_names(std::ostringstream& o, const char* type, const char* what, const std::vector<std::string>& names) {
  o << "/// Named " << what << " layout.\nstruct " << type << " {\n";
  for (std::size_t i = 0; i < names.size(); ++i)
    o << "  static constexpr std::size_t " << constant_name(names[i]) << " = " << i << ";  ///< " << names[i] << "\n";
  o << "};\n\n";
}

}  // namespace

std::string constant_name(const std::string& identifier) {
  std::string out = "k";
  bool upper = true;
  for (char ch : identifier) {
    if (ch == '_') {
      upper = true;
      continue;
    }
    out += upper ? static_cast<char>(std::toupper(static_cast<unsigned char>(ch))) : ch;
    upper = false;
  }
  return out;
}

std::string emit_header(const PlantDescription& plant, const DesignResult& design, const PlantPatterns& pat,
                        const TableData<float>& table_float, const TableData<double>& table_double,
                        const FixedFormats* formats, const TableData<BlockFixedStorage>* table_fixed,
                        const std::string& fixed_unavailable_reason, const std::string& generator) {
  std::ostringstream o;
  // The plant's name and file name are data from the user: escaped, never pasted raw.
  o << "// Generated by " << generator << " from " << cpp_comment_text(plant.source) << ". Do not edit.\n"
    << "// Plant " << cpp_comment_text(plant.name) << ": table of Phi/Gamma/Qd, design constants and structure.\n"
    << "#pragma once\n\n"
    << "/// 1 when the design step found fixed-point formats for this plant (PlantConstants<FixedTag>).\n"
    << "#define ONESHOT_GENERATED_FIXED_POINT " << (formats != nullptr ? 1 : 0) << "\n\n"
    << "#include <cstddef>\n#include <cstdint>\n\n"
    << "#include \"oneshot/controller_design.hpp\"\n"
    << "#include \"oneshot/fixed_point.hpp\"\n"
    << "#include \"oneshot/generic_discretizer.hpp\"\n"
    << "#include \"oneshot/number_format.hpp\"\n"
    << "#include \"oneshot/pattern.hpp\"\n"
    << "#include \"oneshot/table_discretizer.hpp\"\n"
    << "#include \"oneshot/table_view.hpp\"\n\n"
    << "namespace oneshot::generated {\n\n"
    << "/// Name of the plant these constants come from.\n"
    << "inline constexpr char kPlantName[] = " << cpp_string_literal(plant.name) << ";\n\n";
  emit_names(o, "StateIndex", "state", plant.states);
  emit_names(o, "InputIndex", "input", plant.inputs);
  emit_names(o, "OutputIndex", "output", plant.outputs);
  o << "/// Dimensions and structural patterns (derived from the graph of A, B, Q_c).\n"
    << "struct PlantStructure {\n"
    << "  static constexpr std::size_t kStates = " << plant.n() << ";\n"
    << "  static constexpr std::size_t kInputs = " << plant.m() << ";\n"
    << "  static constexpr std::size_t kOutputs = " << plant.p() << ";\n"
    << "  using PhiPattern = " << pat.phi.cpp_type() << ";\n"
    << "  using GammaPattern = " << pat.gamma.cpp_type() << ";\n"
    << "  using QdPattern = " << pat.qd.cpp_type() << ";\n"
    << "  using ConstantQPattern = " << pat.constant_q.cpp_type() << ";\n"
    << "  using OutputPattern = " << pat.output.cpp_type() << ";\n"
    << "  using FeedbackPattern = " << pat.feedback.cpp_type() << ";\n"
    << "  using StateFeedforwardPattern = " << pat.state_feedforward.cpp_type() << ";\n"
    << "  using InputFeedforwardPattern = " << pat.input_feedforward.cpp_type() << ";\n"
    << "};\n\n"
    << "/// Constants in scalar S (specialised for each generated format).\n"
    << "template <typename S>\nstruct PlantConstants;\n\n";
  emit_constants(o, "float", plant, design, table_float);
  emit_constants(o, "double", plant, design, table_double);
  if (formats != nullptr && table_fixed != nullptr) {
    emit_fixed(o, plant, design, *formats, *table_fixed);
  } else {
    std::string reason;
    for (char c : fixed_unavailable_reason) reason += c == '"' || c == '\\' ? '\'' : c;
    o << "/// Why this plant has no fixed-point constants.\n"
      << "inline constexpr char kFixedPointUnavailable[] = \"" << reason << "\";\n\n";
  }
  o << "}  // namespace oneshot::generated\n";
  return o.str();
}

}  // namespace oneshot::design
