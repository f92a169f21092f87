/// @file header_emitter.cpp
/// @brief Generated header text (see header_emitter.hpp).
#include "oneshot/design/header_emitter.hpp"

#include <cctype>
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

template <typename S>
void emit_constants(std::ostringstream& o, const char* scalar, const PlantDescription& plant, const DesignResult& d,
                    const TableData<S>& t) {
  const std::size_t n = plant.n();
  const std::size_t m = plant.m();
  const std::size_t p = plant.p();
  DenseMatrix a_us = plant.a;
  for (double& x : a_us.values) x *= 1e-6;
  DenseMatrix b_us = plant.b;
  for (double& x : b_us.values) x *= 1e-6;
  DenseMatrix qc_us = d.qc;
  for (double& x : qc_us.values) x *= 1e-6;
  o << "/// Constants in " << scalar << ".\n"
    << "template <>\nstruct PlantConstants<" << scalar << "> {\n"
    << "  /// Number formats of every quantity.\n"
    << "  using Format = ::oneshot::UniformFormat<" << scalar << ">;\n"
    << "  static constexpr std::uint16_t kRadix[] = {" << int_list(t.radix) << "};\n"
    << "  static constexpr std::uint16_t kLevelOffset[] = {" << int_list(t.level_offset) << "};\n"
    << "  static constexpr std::int8_t kPhiSlot[] = {" << int_list(t.phi_slot) << "};\n"
    << "  static constexpr std::int8_t kGammaSlot[] = {" << int_list(t.gamma_slot) << "};\n"
    << "  static constexpr std::int8_t kQdSlot[] = {" << int_list(t.qd_slot) << "};\n"
    << "  /// Entry times (us): " << int_list(t.entry_time_us) << ".\n"
    << "  static constexpr " << scalar << " kValues[] = {\n      " << value_list(t.values, t.slots) << "};\n"
    << "  static constexpr std::uint8_t kResidualLow[] = {" << int_list(t.residual_low) << "};\n"
    << "  static constexpr std::uint8_t kResidualHigh[] = {" << int_list(t.residual_high) << "};\n"
    << "  static constexpr std::uint8_t kResidualOffset[] = {" << int_list(t.residual_offset) << "};\n"
    << "  static constexpr " << scalar << " kResidualCoefficients[] = {" << value_list(t.residual_coefficients, 0)
    << "};\n"
    << "  /// The look-up table (" << t.bytes() << " bytes).\n"
    << "  static constexpr ::oneshot::TableView<" << scalar << "> kTable{" << t.granularity_us << ", " << t.range_us
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
                        const std::string& generator) {
  std::ostringstream o;
  o << "// Generated by " << generator << " from " << plant.source << ". Do not edit.\n"
    << "// Plant '" << plant.name << "': table of Phi/Gamma/Qd, design constants and structure.\n"
    << "#pragma once\n\n"
    << "#include <cstddef>\n#include <cstdint>\n\n"
    << "#include \"oneshot/controller_design.hpp\"\n"
    << "#include \"oneshot/generic_discretizer.hpp\"\n"
    << "#include \"oneshot/number_format.hpp\"\n"
    << "#include \"oneshot/pattern.hpp\"\n"
    << "#include \"oneshot/table_discretizer.hpp\"\n"
    << "#include \"oneshot/table_view.hpp\"\n\n"
    << "namespace oneshot::generated {\n\n"
    << "/// Name of the plant these constants come from.\n"
    << "inline constexpr char kPlantName[] = \"" << plant.name << "\";\n\n";
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
  o << "}  // namespace oneshot::generated\n";
  return o.str();
}

}  // namespace oneshot::design
