/// @file plant_parts.hpp
/// @brief Parsers of the plant file's sections other than the dynamics (internal header).
///
/// Each reads its part of the JSON root into a PlantDescription whose dynamics (form,
/// n, m, p, q, C, period) are already set, and refuses bad values naming the field.
#pragma once

#include <nlohmann/json.hpp>

#include "oneshot/design/plant_description.hpp"
#include "plant_json_reader.hpp"

namespace oneshot::design::detail {

/// `cost` (optional): {Q1c, Q2c} (continuous plants) or {Q1 | Qy, Q2}.
void parse_cost(const nlohmann::json& root, PlantDescription& p, const Checker& check);
/// `noise`: process noise (intensity or per period), disturbance noise, R, P0.
void parse_noise(const nlohmann::json& root, PlantDescription& p, const Checker& check);
/// `tracked_outputs` (optional): m output names.
void parse_tracked_outputs(const nlohmann::json& root, PlantDescription& p, const Checker& check);
/// `table` (optional, continuous plants): granularity, range, byte budget.
void parse_table(const nlohmann::json& root, PlantDescription& p, const Checker& check);
/// `board` (optional PWM board, continuous plants) or `actuator` (optional range).
void parse_board_or_actuator(const nlohmann::json& root, PlantDescription& p, const Checker& check);

}  // namespace oneshot::design::detail
