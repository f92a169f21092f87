/// @file float_grid.hpp
/// @brief The float nearest variant's grid table: Φ, Γ, Q_d at every grid point t = k·g,
///        composed at generation time exactly as the job would compose the stored entries.
#pragma once

#include <vector>

#include "oneshot/design/table_builder.hpp"

namespace oneshot::design::cjob {

/// (range/g + 1) × slots values, grid-point-major: entry k holds each slot's value of the
/// triple the core's float TableDiscretizer returns for τ = k·g (the stored entries of the
/// non-zero mixed-radix digits composed in float, finest first; k = 0 the identity). The job
/// then loads one entry instead of composing up to levels − 1 entries per interval, and
/// computes bit for bit what it computed before. Empty when two entries that share a slot
/// come out of the composition different (the slot layout cannot hold them: no grid table).
std::vector<float> composed_float_grid(const TableData<float>& table);

}  // namespace oneshot::design::cjob
