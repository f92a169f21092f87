/// @file plant_description.hpp
/// @brief The plant description file: format, parsing and validation (host only).
///
/// A JSON object in one of three forms (README, "Plant description"):
///  * "continuous" (default): A, B, C, period h; process noise as an intensity Q_c or a
///    per-period covariance; cost continuous (Q1c, Q2c) or discrete (Q1|Qy, Q2);
///  * "discrete": Φ, Γ, C per step T; per-step process covariance; discrete cost; with a
///    continuous cost (Q1c, Q2c), a board or a table it is read as its exact continuous
///    equivalent (zoh_inverse: the form becomes continuous, `from_discrete` set);
///  * "sections": transfer-function sections realized into the discrete form
///    (plant_sections.hpp), with an optional disturbance model appended as exogenous states.
/// Every field is checked; an error names the field and what is wrong, so a bad file never
/// yields a silently wrong design or table. Sizes are bounded by dimension_limits.hpp.
#pragma once

#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "oneshot/design/dense_matrix.hpp"
#include "oneshot/design/plant_sections.hpp"
#include "oneshot/dimension_limits.hpp"

namespace oneshot::design {

/// A plant description that failed validation; what() names the field.
class PlantError : public std::runtime_error {
 public:
  /// A refusal that names no field (an unreadable file, bad JSON …): what() is the message.
  using std::runtime_error::runtime_error;
  /// A refusal of `field` of `source`: what() is "<source>: field '<field>': <reason>".
  PlantError(const std::string& source, const std::string& field, const std::string& reason)
      : std::runtime_error(source + ": field '" + field + "': " + reason), field_(field), reason_(reason) {}
  /// The field refused ("" when the error names none: an unreadable file, bad JSON …).
  const std::string& field() const { return field_; }
  /// Why the field is refused, without the source and the field ("" when no field).
  const std::string& reason() const { return reason_; }

 private:
  std::string field_;
  std::string reason_;
};

/// How the plant's dynamics are given.
enum class PlantForm {
  kContinuous,  ///< ẋ = A x + B u (+ B_w w), sampled with a zero-order hold at h.
  kDiscrete,    ///< x⁺ = Φ x + Γ u (+ B_w w), one step per period T.
  kSections,    ///< Transfer-function sections realized into the discrete form.
};

/// How the control cost is given.
enum class CostForm {
  kNone,        ///< No cost: no LQR gain is designed (estimation-only plants).
  kContinuous,  ///< J = ∫ xᵀQ1c x + uᵀQ2c u dt, sampled exactly over h (continuous plants).
  kDiscrete,    ///< J = Σ xᵀQ1 x + uᵀQ2 u per step (DLQR weights).
};

/// The emulated PWM board around the plant (actuator and ADC models of the harness).
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
  PlantForm form = PlantForm::kContinuous; ///< How the dynamics are given.
  std::vector<std::string> states;         ///< State names (n), valid C identifiers.
  std::vector<std::string> inputs;         ///< Input names (m).
  std::vector<std::string> outputs;        ///< Output names (p).
  std::vector<std::string> disturbances;   ///< Disturbance input names (q, 0 without B_w).
  DenseMatrix a;                           ///< A (n×n, 1/s); continuous form only, else empty.
  DenseMatrix b;                           ///< B (n×m); continuous form only, else empty.
  DenseMatrix phi;                         ///< Φ per step (n×n); discrete and sections forms, else empty.
  DenseMatrix gamma;                       ///< Γ per step (n×m); discrete and sections forms, else empty.
  DenseMatrix c;                           ///< C (p×n).
  DenseMatrix b_w;                         ///< B_w (n×q): continuous (ẋ += B_w w) or per step (x⁺ += B_w w_k); empty when q = 0.
  DenseMatrix c_bar;                       ///< C̄ (m×n): the input disturbance d = C̄ x of an exogenous model (sections), else empty.
  std::size_t exogenous_states = 0;        ///< Trailing states forming an exogenous disturbance model (not controllable by u).
  std::int32_t period_us = 0;              ///< Control period h, or the discrete step T (µs).

  CostForm cost_form = CostForm::kNone;    ///< Which cost fields are set.
  DenseMatrix q1c;                         ///< Continuous state weight Q1c (n×n), kContinuous.
  DenseMatrix q2c;                         ///< Continuous input weight Q2c (m×m), kContinuous.
  DenseMatrix q1;                          ///< Per-step state weight Q1 (n×n; from Qy as CᵀQyC), kDiscrete.
  DenseMatrix q2;                          ///< Per-step input weight Q2 (m×m), kDiscrete.

  DenseMatrix process_intensity;           ///< Q_c: continuous white-noise intensity (n×n, unit²/s), or empty.
  DenseMatrix process_covariance_per_period;  ///< Qn: covariance added per period h / step T (n×n), or empty.
  DenseMatrix disturbance_intensity;       ///< W_c: intensity of w (q×q, per s), continuous only, or empty.
  DenseMatrix disturbance_covariance_per_period;  ///< W: covariance of w_k per step (q×q), or empty.
  DenseMatrix measurement_covariance;      ///< R (p×p) per sample.
  bool has_initial_covariance = false;     ///< Whether P0 was given.
  DenseMatrix initial_covariance;          ///< P0 (n×n) when given.

  bool tracked_outputs_declared = false;   ///< Whether `tracked_outputs` was given.
  std::vector<std::size_t> tracked_outputs;  ///< Outputs the set-point feed-forward tracks (m of them).

  bool has_table = false;                  ///< Whether a `table` section was given (continuous only).
  std::int32_t table_granularity_us = 0;   ///< Table grid step (µs).
  std::int32_t table_range_us = 0;         ///< Table covers [0, range] (µs).
  std::int32_t table_max_bytes = 0;        ///< Byte budget of a table of 4-byte values (doubles get twice).
  bool has_board = false;                  ///< Whether a PWM `board` was given.
  BoardDescription board;                  ///< Emulated board (when has_board).
  bool has_actuator_range = false;         ///< Whether an `actuator` range was given (no PWM board).
  std::vector<double> u_min, u_max;        ///< Actuator range per input (board: the PWM levels).

  /// A discrete plant (Φ, Γ, Q_d per step) read as its exact continuous equivalent, because it
  /// carries a continuous cost (cost.Q1c, Q2c), a board or a table: A, B from the principal
  /// logarithm of [[Φ, Γ], [0, I]] over h, Q_c whose Van Loan sampling is Q_d (zoh_inverse.hpp
  /// zoh_inverse); the form is then continuous and phi, gamma, process_covariance_per_period empty.
  bool from_discrete = false;
  double d2c_relative_error = 0;        ///< from_discrete: ‖e^{[[A, B], [0, 0]]h} − [[Φ, Γ], [0, I]]‖₁ relative.
  double d2c_noise_relative_error = 0;  ///< from_discrete: ‖Q_d(Q_c) − Q_d‖₁ relative.
  double d2c_phi_condition = 1;         ///< from_discrete: κ₁(Φ) (above kZohInverseWarnCondition: A ill-conditioned).
  DenseMatrix d2c_phi;                  ///< from_discrete: the Φ given.
  DenseMatrix d2c_gamma;                ///< from_discrete: the Γ given.

  bool has_sections = false;               ///< Sections form: the specification the model was realized from.
  SectionsDescription sections;            ///< The sections (when has_sections).

  std::size_t n() const { return c.cols; }            ///< Number of states.
  std::size_t m() const { return inputs.size(); }     ///< Number of inputs.
  std::size_t p() const { return c.rows; }            ///< Number of outputs.
  std::size_t q() const { return b_w.cols; }          ///< Number of disturbance inputs.
  bool continuous() const { return form == PlantForm::kContinuous; }  ///< A, B given.
};

/// Name of a form ("continuous", "discrete", "sections").
const char* to_string(PlantForm f);

/// Parses and validates a JSON text; `source` names it in error messages.
PlantDescription parse_plant(const std::string& json_text, const std::string& source);

/// Reads (a regular file of at most 1 MiB), parses and validates a plant file.
PlantDescription load_plant_file(const std::string& path);

/// The built-in default: the reference board (reference_board.json, embedded at build time).
PlantDescription reference_plant();

/// The JSON text of the built-in default.
const std::string& reference_plant_json();

/// PlantError naming `user` and what is missing unless the plant is continuous with a
/// `table` and a `board` (what the one-shot harness and lut_gen's tables need).
void require_continuous_board_and_table(const PlantDescription& plant, const std::string& user);

}  // namespace oneshot::design
