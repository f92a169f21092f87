/// @file c_job_emitter.hpp
/// @brief Writes the C99 control job (oneshot_job.h / oneshot_job.c) for C-only MCU
///        toolchains (XC16 on the reference board's dsPIC33), from the design step's results.
///
/// The job is the one the C++ core runs for approach B — half Kalman filter, one-shot
/// prediction, control law and converters, with the Φ/Γ/Q_d table and exact Q_d(τ) — specialised
/// to the plant: structural zeros and ones skipped, loops unrolled, formats and table indices
/// fixed, grid divisions replaced by exact reciprocal multiplications. Variants, each with its
/// own names (oneshot_job_<variant>_*): fixed_table and fixed_nearest (the fixed-point formats of
/// the design step, bit-identical to the C++ fixed core), float_table and float_nearest (IEEE
/// single, bit-identical to the C++ float core). `table` is the exact sub-grid policy, `nearest`
/// rounds τ to the grid as the original design did.
#pragma once

#include <string>

#include "oneshot/design/controller_synthesis.hpp"
#include "oneshot/design/fixed_formats.hpp"
#include "oneshot/design/plant_description.hpp"
#include "oneshot/design/structure_analysis.hpp"
#include "oneshot/design/table_builder.hpp"

namespace oneshot::design {

/// The generated C files.
struct CJobSources {
  std::string header;           ///< oneshot_job.h
  std::string source;           ///< oneshot_job.c
  std::vector<std::string> variants;  ///< Variant names generated.
  int divisions = 0;            ///< Integer divisions left in the code (no exact 32-bit reciprocal).
};

/// The C job of `plant`; the fixed variants only when `formats` and `table_fixed` are given.
/// `generator` names the tool in the do-not-edit banner.
CJobSources emit_c_job(const PlantDescription& plant, const DesignResult& design, const PlantPatterns& patterns,
                       const TableData<float>& table_float, const FixedFormats* formats,
                       const TableData<BlockFixedStorage>* table_fixed, const std::string& generator);

}  // namespace oneshot::design
