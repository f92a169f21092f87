/// @file synthesis_parts.hpp
/// @brief Parts of the design step after the LQR and the Kalman filter (internal header).
#pragma once

#include <string>

#include "oneshot/design/controller_synthesis.hpp"

namespace oneshot::design::detail {

/// Set-point feed-forward for the tracked outputs into d.nx, d.nu, d.tracking (+ reason).
void design_feedforward(const PlantDescription& plant, DesignResult& d);

/// Current deadbeat observer into d.deadbeat_gain, d.deadbeat (+ reason, residual).
void design_deadbeat(const PlantDescription& plant, DesignResult& d);

/// v with `digits` significant digits (printf %g) for the design step's messages.
std::string significant(double v, int digits);

}  // namespace oneshot::design::detail
