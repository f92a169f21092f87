/// @file plant_description.hpp
/// @brief The plant description file: format, parsing and validation (host only).
///
/// A JSON object (see lut_gen/plants/reference_board.json, the built-in default, and the
/// README's "Plant file" section). Every field is checked; an error names the field and
/// what is wrong, so a bad file never yields a silently wrong design or table.
#pragma once

#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "oneshot/design/dense_matrix.hpp"

namespace oneshot::design {

/// Largest state, input and output dimensions the tools are instantiated for.
inline constexpr std::size_t kMaxStates = 4;
/// Largest input dimension supported.
inline constexpr std::size_t kMaxInputs = 2;
/// Largest output dimension supported.
inline constexpr std::size_t kMaxOutputs = 2;

/// A plant description that failed validation; what() names the field.
class PlantError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The emulated board around the plant (used by the actuator model and the harness).
struct BoardDescription {
  double pwm_frequency_hz = 0;             ///< PWM carrier frequency (Hz).
  std::int32_t pwm_duty_steps = 0;         ///< Duty resolution: codes 0 … steps.
  std::vector<double> pwm_low_volts;       ///< Input voltage while the PWM output is low (per input).
  std::vector<double> pwm_high_volts;      ///< Input voltage while it is high (per input).
  int adc_bits = 0;                        ///< ADC resolution (bits).
  std::vector<double> adc_min_volts;       ///< Voltage at ADC code 0 (per output).
  std::vector<double> adc_max_volts;       ///< Voltage at the top code (per output).
};

/// Validated plant description.
struct PlantDescription {
  std::string name;                        ///< Identifier of the plant.
  std::string description;                 ///< Free text.
  std::string source;                      ///< File it came from ("built-in" for the default).
  std::vector<std::string> states;         ///< State names (n), valid C identifiers.
  std::vector<std::string> inputs;         ///< Input names (m).
  std::vector<std::string> outputs;        ///< Output names (p).
  DenseMatrix a;                           ///< A (n×n, 1/s).
  DenseMatrix b;                           ///< B (n×m).
  DenseMatrix c;                           ///< C (p×n).
  std::int32_t period_us = 0;              ///< Control period h (µs).
  DenseMatrix q1c;                         ///< Continuous state weight Q1c (n×n).
  DenseMatrix q2c;                         ///< Continuous input weight Q2c (m×m).
  DenseMatrix process_covariance;          ///< Qn: process noise covariance per period h (n×n).
  DenseMatrix measurement_covariance;      ///< R (p×p, V²).
  bool has_initial_covariance = false;     ///< Whether P0 was given.
  DenseMatrix initial_covariance;          ///< P0 (n×n) when given.
  std::int32_t table_granularity_us = 0;   ///< Table grid step (µs).
  std::int32_t table_range_us = 0;         ///< Table covers [0, range] (µs).
  std::int32_t table_max_bytes = 0;        ///< Byte budget of a table of 4-byte values (doubles get twice).
  BoardDescription board;                  ///< Emulated board.

  std::size_t n() const { return a.rows; }  ///< Number of states.
  std::size_t m() const { return b.cols; }  ///< Number of inputs.
  std::size_t p() const { return c.rows; }  ///< Number of outputs.
};

/// Parses and validates a JSON text; `source` names it in error messages.
PlantDescription parse_plant(const std::string& json_text, const std::string& source);

/// Reads, parses and validates a plant file (PlantError when unreadable or invalid).
PlantDescription load_plant_file(const std::string& path);

/// The built-in default: the reference board (reference_board.json, embedded at build time).
PlantDescription reference_plant();

/// The JSON text of the built-in default.
const std::string& reference_plant_json();

}  // namespace oneshot::design
