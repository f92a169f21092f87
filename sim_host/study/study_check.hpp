/// @file study_check.hpp
/// @brief `oneshot-sim study check`: a study file resolved into what it implies — the plant
///        (kind, n, m, p), per approach the design (LQR gain, Kalman gain where an estimator
///        runs, spectral radii), per link the delay and loss summary, per CAN bus its load
///        and the worst-case response time of every message, the approaches × scenarios grid.
#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "oneshot/engine/study_file.hpp"
#include "study_ncs_runner.hpp"

namespace oneshot::study {

/// Frame payload the check assumes for a loop message on a CAN bus (bytes; worst case) when
/// the study is not ncs (an ncs file's messages have the loop's sizes, in frames of ≤ 8 bytes).
inline constexpr std::size_t kLoopFramePayloadBytes = 8;

/// A duration in µs, as the check's JSON gives durations.
inline double to_us(engine::Duration d) { return static_cast<double>(d.count()) * 1e-3; }

/// Everything `file` implies, as JSON. Per CAN bus its load and every message's worst-case
/// response (can_analysis.hpp): a loop message of study ncs at the loop's size in frames of
/// ≤ 8 bytes, its release jitter chained through the links before it (a link on a bus adding
/// [C, R] of its message; the buses analysed together to a fixed point). engine::InputError naming the field for an
/// undetectable or unstabilizable design ("plant"), a plant file that does not load
/// ("plant.file"), a bus loaded over 100 % ("buses[i]") or a bus message without a period.
/// Approach kinds of study ncs get their design (I, S, A: LQR; AK, AKx, AKl, SK, IK: LQR and
/// Kalman; S+: the gain on eq. 8 per scenario); inline plants are summarized but not designed
/// (they carry no measurement covariance).
nlohmann::json resolve_study(const engine::StudyFile& file);

/// Adds to the resolution `r` of an ncs file what needs its scenarios: the S+ gain
/// [L_x, L_u] and the mean delay τ_io it is designed on, and AKl's D (late_sampling_d_us:
/// max sc + max ca + max τ_c, the controller job's WCRT on a CPU), per scenario.
void add_ncs_designs(nlohmann::json& r, const NcsStudy& s);

/// Sets s.bus_response_us from the resolution `r` of the same file: per scenario the
/// worst-case response time of each leg on a bus (the scenario's own analysis where it has one).
void attach_bus_bounds(NcsStudy& s, const nlohmann::json& r);

/// The resolution as text, one fact per line.
std::string describe_resolution(const nlohmann::json& r);

}  // namespace oneshot::study
