/// @file sod_report.hpp
/// @brief The send-on-delta study's section of `oneshot-sim report`.
#pragma once

#include "oneshot/sim/study_report.hpp"

namespace oneshot::sod {

/// Runs the design, E1–E4 on the built-in defaults into ctx.out_dir and returns the
/// markdown section ("## Send-on-delta …") and its JSON.
sim::StudyReportResult report_section(const sim::StudyReportContext& ctx);

}  // namespace oneshot::sod
