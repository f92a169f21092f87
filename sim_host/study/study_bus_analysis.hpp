/// @file study_bus_analysis.hpp
/// @brief The CAN buses of a study file analysed for `study check`: per bus its load and the
///        worst-case response time of every message (background streams and the loop's links,
///        engine can_analysis.hpp), with the release jitter of each loop message chained back
///        to a timer node through the links before it, buses included.
#pragma once

#include <nlohmann/json.hpp>

#include "oneshot/engine/study_file.hpp"

namespace oneshot::study {

/// Per bus of `f` (file order): name, bit_rate, load, messages (per stream: name, kind,
/// id, payload_bytes, frames, message_bytes, period_us, jitter_us, deadline_us,
/// transmission_us, bounded, schedulable, worst_response_us) and, for a scenario whose link
/// overrides change them, scenarios.<name> (the messages again). A loop message of study ncs
/// is taken at the loop's size in frames of ≤ 8 bytes, of another study as one 8-byte frame;
/// it is released once per period of its sender (a timer node's, else the file's smallest),
/// deadline = period, its jitter the spread of its sender's send window (a link on a bus adds
/// [C, R] of its message: every bus analysed from R = C until the responses stop growing; one
/// still growing after 64 rounds is taken unbounded). engine::InputError naming `buses[i]` for
/// a bus over 100 % load or a loop message without a period.
nlohmann::json analyze_buses(const engine::StudyFile& f);

}  // namespace oneshot::study
