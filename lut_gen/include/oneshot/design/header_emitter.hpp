/// @file header_emitter.hpp
/// @brief Writes the generated C++ header the firmware and the harness compile against.
///
/// The header holds, for float, double and the fixed-point formats (PlantConstants<float>,
/// <double>, <FixedTag>): the table (TableView and its arrays), the ControllerDesign
/// constants, the per-µs continuous model for the generic routine; and once: the named
/// state layout, the compile-time PlantStructure (patterns) and FixedFormat. When the
/// design step finds no fixed-point formats for the plant (formats == nullptr), the header
/// says so: ONESHOT_GENERATED_FIXED_POINT is 0 and kFixedPointUnavailable gives the reason.
/// Values are written as hexadecimal floating literals, exact in their format.
#pragma once

#include <string>

#include "oneshot/design/controller_synthesis.hpp"
#include "oneshot/design/fixed_formats.hpp"
#include "oneshot/design/plant_description.hpp"
#include "oneshot/design/structure_analysis.hpp"
#include "oneshot/design/table_builder.hpp"

namespace oneshot::design {

/// The header text; `generator` names the tool in the do-not-edit banner.
std::string emit_header(const PlantDescription& plant, const DesignResult& design, const PlantPatterns& patterns,
                        const TableData<float>& table_float, const TableData<double>& table_double,
                        const FixedFormats* formats, const TableData<BlockFixedStorage>* table_fixed,
                        const std::string& fixed_unavailable_reason, const std::string& generator);

/// "v1" → "kV1", "x_dot" → "kXDot".
std::string constant_name(const std::string& identifier);

}  // namespace oneshot::design
