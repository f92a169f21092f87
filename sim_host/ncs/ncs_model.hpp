/// @file ncs_model.hpp
/// @brief Study `ncs` (networked-actuation brief): the plant and design, the approaches,
///        the ten scenarios, and the S+ design on eq. 8.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "oneshot/controller_design.hpp"
#include "oneshot/design/controller_synthesis.hpp"
#include "oneshot/design/plant_description.hpp"
#include "oneshot/engine/can_analysis.hpp"
#include "oneshot/engine/can_bus.hpp"
#include "oneshot/engine/link.hpp"
#include "oneshot/generic_discretizer.hpp"
#include "oneshot/number_format.hpp"

namespace oneshot::ncs {

inline constexpr std::size_t kN = 2;  ///< States v1, v2.
inline constexpr std::size_t kM = 1;  ///< One input.
inline constexpr std::size_t kP = 2;  ///< Both states measured (C = I).
using Fmt = UniformFormat<double>;

/// A loop's plant shape: n states, m inputs, p outputs, and the design types of that shape.
/// The loops the study files run (I, S, SK, IK) take it as a template parameter
/// (ncs_harness.hpp); ncs_loop.cpp instantiates them for each shape of ONESHOT_NCS_SHAPES.
template <std::size_t N, std::size_t M, std::size_t P>
struct Shape {
  static constexpr std::size_t n = N;  ///< States.
  static constexpr std::size_t m = M;  ///< Inputs.
  static constexpr std::size_t p = P;  ///< Outputs.
  using Design = ControllerDesign<Fmt, N, M, P>;  ///< The controller design of this shape.
  using Disc = GenericDiscretizer<Fmt, N, M>;     ///< Its discretizer.
};
/// The board's shape (2, 1, 2): every approach runs on it (the others: I, S, SK, IK only).
using BoardShape = Shape<kN, kM, kP>;
/// The largest plant the study files run: n ≤ 16 states, m ≤ 4 inputs, p ≤ 4 outputs.
inline constexpr std::size_t kMaxNcsStates = 16;
inline constexpr std::size_t kMaxNcsInputs = 4;   ///< m ≤ 4.
inline constexpr std::size_t kMaxNcsOutputs = 4;  ///< p ≤ 4.
/// The largest state count whose state fits one sensor frame (node::kMaxMessageBytes = 64:
/// 8 header + 8n + 2 CRC bytes): the reference loop I sends x, so it runs for n ≤ 6 only.
inline constexpr std::size_t kMaxStateFeedbackStates = 6;
/// The shapes the loops are instantiated for, as X(n, m, p) (the board's first): the exact
/// shapes, the board's (2, 1, 2), a first-order plant (1, 1, 1: the closed forms of a scalar
/// loop are its oracles) and a cart-pole-like plant with its four states measured (4, 1, 4);
/// then the capacity shapes (6, 4, 4), (8, 4, 4) and (16, 4, 4). A plant runs on its exact shape when it is
/// listed, else embedded (zero padding: ncs_shape_of()) in the first listed shape that holds it:
/// its padded states, inputs and outputs are inert (A, B, C, Q_c, Q1c, Q2c, L, N_x, N_u, Φ, Γ,
/// Q_d, P0 0 there, R 1 on the padded diagonal, the padded inputs' range [−1, 1] holding their 0),
/// and only the real dimensions draw noise: the padded run is the plant's own run. (6, 4, 4)
/// holds every plant whose state fits the sensor frame of I (n ≤ 6): I runs on it; (8, 4, 4)
/// the plants of n = 7, 8 (e.g. four structural modes) at half the matrices of (16, 4, 4),
/// which holds the rest (a padded run does the larger shape's arithmetic: a plant of n = 8 runs
/// 3.2 times faster on (8, 4, 4) than on (16, 4, 4)). Each shape costs one instantiation of the
/// sampling loops in ncs_loop.cpp (about 1–3 s of its compile time).
#define ONESHOT_NCS_SHAPES(X) X(2, 1, 2) X(1, 1, 1) X(4, 1, 4) X(6, 4, 4) X(8, 4, 4) X(16, 4, 4)
/// The shapes of ONESHOT_NCS_SHAPES in words, for refusals.
inline constexpr const char* kNcsShapesText =
    "n <= 16 states, m <= 4 inputs, p <= 4 outputs (every approach on the board's shape n = 2, m = 1, p = 2 with C = I; "
    "I, S, SK, IK on another)";
/// The shape (N, M, P) of ONESHOT_NCS_SHAPES a plant of n states, m inputs, p outputs runs on:
/// its own when listed, else the first that holds it; {0, 0, 0} when none does.
struct NcsShapeOf {
  std::size_t n = 0;  ///< N.
  std::size_t m = 0;  ///< M.
  std::size_t p = 0;  ///< P.
  /// True when the plant runs padded (its shape is not listed).
  bool padded = false;
};
/// ncs_shape_of(n, m, p): the shape the loops run a plant of n states, m inputs, p outputs on.
constexpr NcsShapeOf ncs_shape_of(std::size_t n, std::size_t m, std::size_t p) {
  if (n < 1 || m < 1 || p < 1) return {};
#define ONESHOT_NCS_SHAPE_IS(n_, m_, p_) \
  if (n == (n_) && m == (m_) && p == (p_)) return NcsShapeOf{n_, m_, p_, false};
  ONESHOT_NCS_SHAPES(ONESHOT_NCS_SHAPE_IS)
#undef ONESHOT_NCS_SHAPE_IS
#define ONESHOT_NCS_SHAPE_HOLDS(n_, m_, p_) \
  if (n <= (n_) && m <= (m_) && p <= (p_)) return NcsShapeOf{n_, m_, p_, true};
  ONESHOT_NCS_SHAPES(ONESHOT_NCS_SHAPE_HOLDS)
#undef ONESHOT_NCS_SHAPE_HOLDS
  return {};
}
/// True when the loops run a plant of n states, m inputs, p outputs (exact or embedded).
constexpr bool ncs_shape_runs(std::size_t n, std::size_t m, std::size_t p) { return ncs_shape_of(n, m, p).n != 0; }
/// True for the board's shape (2, 1, 2): every approach, --analytic and the live run.
constexpr bool board_shape(std::size_t n, std::size_t m, std::size_t p) { return n == kN && m == kM && p == kP; }

using Design = BoardShape::Design;
using Disc = BoardShape::Disc;

/// The approaches of brief §5, in table order (I first: the reference of every ratio), then
/// the one-shot loops of study files (kOneShotApproaches; not in study ncs's table).
enum class Approach : std::uint8_t { kI, kS, kA, kAK, kAKx, kAKl, kSK, kSPlus, kIK, kOS, kOSp, kOSK };
inline constexpr std::array<Approach, 9> kAllApproaches = {Approach::kI,   Approach::kS,   Approach::kA,
                                                           Approach::kAK,  Approach::kAKx, Approach::kAKl,
                                                           Approach::kSK,  Approach::kSPlus, Approach::kIK};
/// The one-shot loops (study files): sensor on its timer at kh (send-on-delta for OS and OSp,
/// every sample for OSK), controller on its timer at kh + φ (Scenario::controller_phase_us)
/// correcting with what arrived (OS: a silent sensor's held value with R̄ = R + ((d+1)δy)²/3;
/// OSp and OSK: predict only) and computing u_{k+1}, actuator on its timer applying it at (k+1)h.
inline constexpr std::array<Approach, 3> kOneShotApproaches = {Approach::kOS, Approach::kOSp, Approach::kOSK};
/// True for the one-shot loops (OS, OSp, OSK).
constexpr bool one_shot(Approach a) { return a == Approach::kOS || a == Approach::kOSp || a == Approach::kOSK; }
/// True for the approaches every plant shape runs (I, S, SK, IK; I for n ≤ 6 and S for C = I
/// only); the others run on the board's shape only.
constexpr bool any_shape_approach(Approach a) {
  return a == Approach::kI || a == Approach::kS || a == Approach::kSK || a == Approach::kIK;
}
/// True for the loops whose controller runs a Kalman filter with a covariance P (AK, AKx,
/// AKl, SK, IK, OS, OSp, OSK): the ones with a NEES.
constexpr bool filtered_approach(Approach a) {
  return a == Approach::kAK || a == Approach::kAKx || a == Approach::kAKl || a == Approach::kSK || a == Approach::kIK ||
         one_shot(a);
}
/// Short name ("I", "S", "A", "AK", "AKx", "AKl", "SK", "S+", "IK", "OS", "OSp", "OSK").
const char* name(Approach a);
/// One-line description.
const char* description(Approach a);
/// Approach of study ncs (kAllApproaches) from its name; std::invalid_argument listing the names otherwise.
Approach parse_approach(const std::string& text);
/// Any approach from its name, the one-shot loops of study files included (kOneShotApproaches);
/// std::invalid_argument listing the names otherwise.
Approach parse_any_approach(const std::string& text);
/// True for the actuation-synchronized loops (A, AK, AKx, AKl).
bool actuation_synchronized(Approach a);
/// True for the ideal loops without delays (I, IK).
bool delay_free(Approach a);

/// A leg on a CAN bus (study files): the bus, the leg's identifier and the bus's other
/// traffic (periodic streams, their first releases). Its delay is the bus's: arbitration
/// by identifier, the message in frames of ≤ 8 bytes (network.hpp), no loss.
struct BusLeg {
  engine::CanBusConfig bus;                 ///< Name, bit rate, identifier length.
  std::uint32_t id = 0;                     ///< The leg's identifier.
  std::vector<engine::CanStream> background;  ///< Other traffic on the bus (can_traffic.hpp).
  std::vector<engine::Duration> offsets;    ///< First release of each background stream.
};

struct ControllerCpu;  // ncs_cpu.hpp

/// The one-shot filter's prediction over one period: Φ(h), Γ(h) and Q_d(h) at noise scale 1
/// (x_{k+1} = Φ x_k + Γ u_k + w_k, E[w wᵀ] = s·Q_d): from a study file's table discretizer
/// (study_one_shot_discretizer.hpp) instead of the design's exact triple.
struct OneShotTriple {
  Matrix<double, kN, kN> phi;    ///< Φ(h).
  Matrix<double, kN, kM> gamma;  ///< Γ(h).
  Matrix<double, kN, kN> qd;     ///< Q_d(h) at s = 1.
};

/// One scenario (brief §3): square wave ±A_r of period T_r, network legs U[0.5, d] ms,
/// noise scale s.
struct Scenario {
  std::string name;              ///< e.g. "a0.2-T2-d4-s1".
  double amplitude_volts = 0;    ///< A_r.
  double period_s = 0;           ///< T_r.
  double max_delay_ms = 0;       ///< d.
  double noise_scale = 1;        ///< s.
  double duration_s = 20;        ///< Run length.
  /// Legs "as", "sc", "ca" given by a study file (delay, loss, order; the frame layout stays
  /// the loop's). Empty: the brief's legs U[0.5, d] ms in whole µs, FIFO, lossless. When set,
  /// d is not used by the loop: S+ designs on the legs' mean delays and AKl's D is the sum of
  /// their upper bounds.
  std::map<std::string, engine::LinkConfig> legs;
  /// Legs on a CAN bus (study files), by name: not in `legs`. The delay-free loops (I, IK)
  /// keep their delay-free links.
  std::map<std::string, BusLeg> bus_legs;
  /// The controller's computation as a job on a modeled CPU (study files' `cpus`,
  /// ncs_cpu.hpp): τ_c is its response time in the schedule instead of U[1, 5] ms; null:
  /// the draw. The delay-free loops (I, IK) keep τ_c = 0.
  std::shared_ptr<const ControllerCpu> controller_cpu;
  /// The sensor's sampling job on a modeled CPU (ncs_cpu.hpp; S and SK only, else
  /// std::invalid_argument): it samples at the job's sample point and sends at its finish;
  /// null: the sensor samples and sends at kh.
  std::shared_ptr<const ControllerCpu> sensor_cpu;
  /// τ_c ~ U[first, second] in whole µs instead of Timing's U[1, 5] ms (without a CPU; study
  /// files do not set it: a constant τ_c is the oracle of a lone constant job on a CPU).
  std::optional<std::pair<std::int64_t, std::int64_t>> compute_us;
  /// One-shot loops (OS, OSp): the sensor's send-on-delta thresholds δy per output (empty:
  /// every sample) and its time rule n_t in samples (0: plain send-on-delta), from a study file.
  std::vector<double> sod_delta;
  std::uint32_t sod_time_steps = 0;  ///< n_t of the send-on-delta rule (0: off).
  /// One-shot loops (OS, OSp): the sensor's MTM rule instead of send-on-delta (node::MtmTrigger:
  /// send when (ȳ_i − y_i)² > σ y_i² + δ, after k_max silent samples, k_ref,max samples after a
  /// set-point change); OS then needs σ = 0 (its held value within ±√δ: δy = √δ, n_t = k_max).
  bool sensor_mtm = false;
  double mtm_sigma = 0;             ///< σ of the MTM rule.
  double mtm_delta = 0;             ///< δ of the MTM rule (V²).
  std::uint32_t mtm_k_max = 0;      ///< k_max of the MTM rule (0: off).
  std::uint32_t mtm_k_ref_max = 0;  ///< k_ref,max of the MTM rule.
  /// One-shot loops: the controller's timer fires φ after each sampling instant, at kh + φ
  /// (0 < φ < h; std::invalid_argument otherwise).
  std::int64_t controller_phase_us = 0;
  /// One-shot loops: the filter's Φ(h), Γ(h), Q_d(h) per approach (index in kOneShotApproaches:
  /// OS, OSp, OSK) from a study file's `params.discretizer` "table" or "nearest"; null: the
  /// design's exact triple ("generic", the default).
  std::array<std::shared_ptr<const OneShotTriple>, 3> one_shot_triples;
  /// A stepped set-point (a study file's `reference` of kind steps or file) on the kh grid: the
  /// changes (period k > 0, new value), k strictly increasing, set_steps(); null: the square
  /// wave ±A_r of period T_r.
  std::shared_ptr<const std::vector<std::pair<std::uint64_t, double>>> setpoint_changes;
  double setpoint_r0 = 0;            ///< r_0 of the stepped set-point (before its first change).
  std::string setpoint_description;  ///< The stepped set-point in one line (the sweep's configuration).
  /// The nodes' clock offsets φ (whole µs; a study file's `nodes[i].clock_offset_us`, 0 ≤ φ < h;
  /// a run takes the timer node's in [0, h), the others' in (−h, h): at_phase_zero()):
  /// a node's clock reads t − φ, so its timer at local kh fires at true kh + φ and its stamps
  /// lag true time by φ. The loop's timer node gives the loop's phase (the sensor's for I, S,
  /// SK, S+, IK; the actuator's for A, AK, AKx, AKl): the loop, its plant and set-point, shift
  /// by it (LoopOnBus::clock_offset_us). The other nodes' offsets against it are clock
  /// disagreements: the synchronized loops' sensor reads the actuator's t_k on its own clock
  /// (τ_k biased by φ_s − φ_a); the controller's clock enters only through differences; the
  /// sampling loops' controller and actuator read none. The one-shot loops take none (0).
  std::int64_t sensor_clock_us = 0;
  std::int64_t controller_clock_us = 0;  ///< The controller's φ_c (sensor_clock_us).
  std::int64_t actuator_clock_us = 0;    ///< The actuator's φ_a (sensor_clock_us).
};

/// True when a node of `s` runs a clock offset (Scenario::sensor_clock_us).
inline bool has_clock_offsets(const Scenario& s) {
  return s.sensor_clock_us != 0 || s.controller_clock_us != 0 || s.actuator_clock_us != 0;
}
/// The loop's phase φ of approach `a` on `s` run alone: its timer node's clock offset (the
/// actuator's for A, AK, AKx, AKl; the sensor's for I, S, SK, S+, IK; 0 for the one-shot loops).
std::int64_t loop_phase_us(Approach a, const Scenario& s);
/// `s` with every node's clock offset less the loop's phase of `a` (loop_phase_us()): the same
/// loop at phase 0, the same cost to the bit (the timer node's clock then reads t, the others
/// t − (φ_i − φ), possibly negative); what a trace runs (the trace is on the run's time).
Scenario at_phase_zero(Scenario s, Approach a);

/// Puts the steps (t_s, value) (times strictly increasing, the set-point 0 before the first)
/// on the kh grid of `sc`: each step from the first period k with kh ≥ t_s (to the ns), r_0
/// the value at k = 0, a change wherever the value differs from the period before.
/// std::invalid_argument naming the steps' indices when two steps fall in one period, or,
/// when `lines` gives each step's line in the file `source`, the file and its lines.
void set_steps(Scenario& sc, std::int64_t h_us, const std::vector<std::pair<double, double>>& steps,
               const std::vector<std::size_t>& lines = {}, const std::string& source = "");

/// True when the legs come from a study file (point to point or on a bus), not from d.
inline bool legs_from_file(const Scenario& s) { return !s.legs.empty() || !s.bus_legs.empty(); }
/// The ten scenarios of brief §3.
std::vector<Scenario> default_scenarios();
/// Scenarios from the text of a scenario file {"description", "scenarios": [{"name",
/// "amplitude_volts", "period_s", "max_delay_ms", "noise_scale", "duration_s"}]}, every
/// field checked (engine::InputError naming it); `source` names the file in errors.
std::vector<Scenario> parse_scenarios(const std::string& text, const std::string& source);
/// Scenarios from a file (sim_host/ncs/scenarios.json holds the defaults).
std::vector<Scenario> load_scenarios(const std::string& path);
/// Every scenario's fields as text ("A_r 0.2 V, T_r 2 s, d 4 ms, s 1").
std::string describe(const Scenario& s);

/// Network and computation timing of the study (µs).
struct Timing {
  std::int64_t leg_min_us = 500;      ///< Smallest network-leg delay.
  std::int64_t compute_min_us = 1000; ///< τ_c ~ U[1, 5] ms.
  std::int64_t compute_max_us = 5000;
};

/// The plant, its design, and the per-scenario pieces the controllers need.
class Context {
 public:
  /// Loads the plant file (empty: the built-in default lut_gen/plants/networked_board.json)
  /// and runs the design step; std::invalid_argument when the plant is past n = 16, m = 4,
  /// p = 4 (naming A, B or C), not continuous, has no board, LQR gain or feed-forward.
  static std::shared_ptr<const Context> load(const std::string& plant_path);
  /// The same from a plant description already parsed (a study file's inline plant).
  static std::shared_ptr<const Context> from(design::PlantDescription plant);
  /// load() for the commands that run the board's shape only (the live run, its replay, the
  /// fault table, the stationary costs): std::invalid_argument for another shape.
  static std::shared_ptr<const Context> load_board(const std::string& plant_path);

  const design::PlantDescription& plant() const { return plant_; }  ///< The plant file.
  const design::DesignResult& design() const { return design_; }    ///< The design step's result.
  std::int32_t period_us() const { return plant_.period_us; }       ///< h.
  const Timing& timing() const { return timing_; }                  ///< Delay/computation ranges.
  std::size_t states() const { return plant_.a.rows; }               ///< n.
  std::size_t inputs() const { return plant_.b.cols; }               ///< m.
  std::size_t outputs() const { return plant_.c.rows; }              ///< p.
  /// True when C = I (p = n): the loop S may feed y back as x, P0 = 10·R.
  bool identity_output() const { return identity_output_; }
  /// True for a plant of the board's shape (2, 1, 2) with C = I: every approach, --analytic, buses.
  bool board() const { return board_shape(states(), inputs(), outputs()) && identity_output_; }

  /// The controller design at noise scale s: R = s·R_n, Q = s·Q_n (constant), P0 = 10·R.
  Design controller_design(double noise_scale) const { return controller_design_of<BoardShape>(noise_scale); }
  /// The continuous model (per µs) at noise scale s (Q_c scaled), for the discretizer.
  Disc::Model discretizer_model(double noise_scale) const { return discretizer_model_of<BoardShape>(noise_scale); }
  /// controller_design() for the plant embedded in shape S (one of ONESHOT_NCS_SHAPES holding
  /// it; zero padded: L, N_x, N_u, C, Φ, Γ, Q, Q_d, P0 0, R 1 on the padded diagonal, the padded
  /// inputs' range [−1, 1], sensor scale 1, offset 0). P0 = 10·R when C = I (brief §3), else
  /// s·P0 of the design step (its initial covariance, or the Kalman prior at s = 1).
  template <typename S>
  typename S::Design controller_design_of(double noise_scale) const;
  /// discretizer_model() for the plant embedded in shape S (A, B, Q_c zero padded).
  template <typename S>
  typename S::Disc::Model discretizer_model_of(double noise_scale) const;
  /// Worst τ_sc + τ_c + τ_ca of a scenario (µs): D of late sampling (std::invalid_argument
  /// when a leg of the study file has no upper bound).
  std::int32_t worst_chain_us(const Scenario& s) const;
  /// Mean τ_io = τ_sc + τ_c + τ_ca of a scenario (µs); a leg on a CAN bus adds 0 (its mean
  /// delay is not known before the run: study files refuse S+ on bus legs).
  double mean_tau_io_us(const Scenario& s) const;

 private:
  design::PlantDescription plant_;
  design::DesignResult design_;
  Timing timing_;
  bool identity_output_ = false;
};

/// Sum of the upper delay bounds of the legs "sc" and "ca" of a study-file scenario (a leg it
/// does not set adds 0); std::nullopt when one has no bound (Poisson, lognormal, Pareto) or is
/// on a CAN bus (its bound is the bus analysis's), that leg's name then in *unbounded_leg when given.
std::optional<engine::Duration> sc_ca_delay_bound(const Scenario& s, const char** unbounded_leg = nullptr);

/// The first period k > 0 whose set-point differs from the initial one: T_r/2 in periods for
/// the square wave (0 at amplitude 0), the first change of steps (0 when they never change).
std::uint64_t first_setpoint_change(const Context& ctx, const Scenario& sc);

/// Periods h in half a set-point period; std::invalid_argument unless whole.
std::uint64_t half_wave_periods(const Context& ctx, const Scenario& sc);

/// The S+ gain: LQR on eq. 8 with a constant τ (µs) on ξ = [x_k; u_{k−1}], the continuous
/// cost sampled exactly over the period with the input switching at τ;
/// u_k = −[L_x, L_u] ξ. Returns the 1×3 gain.
std::array<double, kN + kM> delay_compensated_gain(const Context& ctx, double tau_us);

/// The S+ gain as the law takes it: u_k = −L_x x_k − L_u u_{k−1}.
struct SplitGain {
  Matrix<double, kM, kN> lx;  ///< L_x.
  Matrix<double, kM, kM> lu;  ///< L_u.
};
/// delay_compensated_gain() at τ (µs), split into L_x and L_u.
SplitGain delay_compensated_split(const Context& ctx, double tau_us);

}  // namespace oneshot::ncs
