/// @file sweep_registry.hpp
/// @brief Where studies register how a merged sweep becomes their outputs, so the
///        study-agnostic `oneshot-sim merge` can finish any sweep from its shard files.
#pragma once

#include <functional>
#include <nlohmann/json.hpp>
#include <string>

#include "oneshot/engine/sweep.hpp"

namespace oneshot::engine {

/// Turns a complete sweep into the experiment's JSON summary and files in `out_dir`.
using SweepSummarizer = std::function<nlohmann::json(const SweepResults& results, const std::string& out_dir, bool plots)>;

/// Registers the summarizer of sweeps whose spec has this study and experiment (at start-up).
void register_summarizer(const std::string& study, const std::string& experiment, SweepSummarizer summarizer);

/// The summarizer of (study, experiment); std::invalid_argument listing the known ones.
const SweepSummarizer& find_summarizer(const std::string& study, const std::string& experiment);

}  // namespace oneshot::engine
