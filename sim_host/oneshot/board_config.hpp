/// @file board_config.hpp
/// @brief The emulator configuration of a plant description (its "board" section).
#pragma once

#include <cmath>
#include <cstddef>

#include "oneshot/design/controller_synthesis.hpp"
#include "oneshot/design/fixed_size.hpp"
#include "oneshot/design/plant_description.hpp"
#include "board_plant.hpp"
#include "oneshot/sim/random_stream.hpp"

namespace oneshot::sim {

using engine::BoardPlant;
using engine::CircuitConfig;
using engine::CostBreakdown;
using engine::PwmUpdate;

/// Emulator options not in the plant file.
struct BoardOptions {
  PwmUpdate update = PwmUpdate::kImmediate;  ///< Duty register behaviour.
  bool process_noise = true;                 ///< Inject process noise.
};

/// CircuitConfig of `plant` (A, B, C, Q_c = Qn/h, cost weights, PWM and ADC).
template <std::size_t N, std::size_t M, std::size_t P>
CircuitConfig<N, M, P> circuit_config(const design::PlantDescription& plant, const design::DesignResult& d,
                                      const BoardOptions& options) {
  CircuitConfig<N, M, P> c;
  c.a = design::to_fixed<double, N, N>(plant.a);
  c.b = design::to_fixed<double, N, M>(plant.b);
  c.c = design::to_fixed<double, P, N>(plant.c);
  c.qc = design::to_fixed<double, N, N>(d.qc);
  c.q1c = design::to_fixed<double, N, N>(plant.q1c);
  c.q2c = design::to_fixed<double, M, M>(plant.q2c);
  c.nx = design::to_fixed<double, N, P>(d.nx);
  c.nu = design::to_fixed<double, M, P>(d.nu);
  c.pwm_period_ns = std::llround(1e9 / plant.board.pwm_frequency_hz);
  c.duty_steps = plant.board.pwm_duty_steps;
  c.v_low = design::to_fixed<double, M>(plant.board.pwm_low_volts);
  c.v_high = design::to_fixed<double, M>(plant.board.pwm_high_volts);
  c.update = options.update;
  c.adc_bits = plant.board.adc_bits;
  c.adc_min = design::to_fixed<double, P>(plant.board.adc_min_volts);
  c.adc_lsb = design::to_fixed<double, P>(d.volts_per_code);
  c.process_noise = options.process_noise;
  return c;
}

}  // namespace oneshot::sim
