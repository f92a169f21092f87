/// @file filter_cases.hpp
/// @brief The cases of the parameterized one-shot filter tests (kalman_filters_test,
///        fixed_kalman_test): which filter, which noise model, which discretizer.
#pragma once

#include <gtest/gtest.h>

#include <ostream>
#include <string>

#include "oneshot/controller_design.hpp"

namespace oneshot::test {

/// The one-shot filter a case runs.
enum class FilterVariant { kHalf, kComplete };

/// One case: its name (also the test name's suffix), the filter, Q_d's model, and the
/// discretizer (the Φ(τ) table, else the generic one).
struct FilterCase {
  const char* name;       ///< e.g. "half_table_exact".
  FilterVariant variant;  ///< Half or complete filter.
  NoiseModel noise;       ///< Exact Q_d(τ) or the constant one.
  bool table;             ///< Table discretizer (else generic).
};

/// GoogleTest prints a case by its name.
inline void PrintTo(const FilterCase& c, std::ostream* os) { *os << c.name; }

/// The test name's suffix of a case.
inline std::string filter_case_name(const ::testing::TestParamInfo<FilterCase>& info) { return info.param.name; }

}  // namespace oneshot::test
