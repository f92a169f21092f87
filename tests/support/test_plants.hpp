/// @file test_plants.hpp
/// @brief Plant descriptions used across tests (reference and non-nilpotent plants).
#pragma once

#include <string>

#include "oneshot/design/plant_description.hpp"

namespace oneshot::test {

/// JSON of a plant with the given A, B, C (JSON arrays as text) and reference-like
/// remaining fields; `extra` replaces fields by name (a JSON object as text).
std::string plant_json(const std::string& a, const std::string& b, const std::string& c,
                       const std::string& extra = "{}");

/// Damped oscillator ω = 30 rad/s, ζ = 0.2 (complex poles, not nilpotent).
design::PlantDescription damped_oscillator();

/// Plant with an unstable real pole (+8 1/s) and a stable one (−15 1/s).
design::PlantDescription unstable_plant();

/// Three-state chain with damping (dense Φ).
design::PlantDescription three_state_plant();

/// The reference JSON with the value at `pointer` (JSON pointer, e.g. "/noise/R")
/// replaced by `value_json`, or removed when value_json is empty.
std::string reference_with(const std::string& pointer, const std::string& value_json);

}  // namespace oneshot::test
