/// @file study_file.hpp
/// @brief The study file: plant + nodes + links (+ CAN buses) + approaches + scenarios, in
///        JSON, parsed strictly (docs/engine.md has the schema with an example).
///
/// parse_study() takes the text and a source name only (no other input), so a fuzzing
/// harness can call it on any string; delay-trace files named inside are read relative to
/// `base_dir`. Every error is an InputError naming the field ("links[1].delay.max_us:
/// below min_us"). Unknown and duplicate keys are refused, numbers are range-checked,
/// names are unique, and every link connects declared nodes. What a study does with its
/// approaches and scenarios is its own code: a StudySchema lists the approach kinds and
/// the numeric parameters it accepts (range, integer or not, required or default), and
/// parse_study() checks the file against it; without a schema any kind and any finite
/// numeric parameter pass.
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "oneshot/engine/can_analysis.hpp"
#include "oneshot/engine/can_bus.hpp"
#include "oneshot/engine/cpu_task_set.hpp"
#include "oneshot/engine/delay_model.hpp"
#include "oneshot/engine/json_fields.hpp"
#include "oneshot/engine/link.hpp"
#include "oneshot/engine/loss_model.hpp"
#include "oneshot/engine/plant_model.hpp"

namespace oneshot::design {
struct PlantDescription;
}  // namespace oneshot::design

namespace oneshot::engine {

/// The version string the "schema" field must hold.
inline constexpr const char* kStudySchemaVersion = "oneshot-study/1";

/// A parameter a study accepts for its approaches or scenarios: a number, or (with `words`)
/// one of a list of words.
struct ParamSpec {
  std::string name;         ///< Key in "params".
  double min = 0;           ///< Smallest value.
  double max = 0;           ///< Largest value.
  bool integer = false;     ///< Must be a whole number.
  bool required = false;    ///< Must be given (else `fallback`).
  double fallback = 0;      ///< Value when absent.
  /// Non-empty: a word parameter, one of these strings (ApproachSpec::words; absent: not
  /// filled in, the study's mapping decides); min, max, integer, fallback unused.
  std::vector<std::string> words = {};
};

/// What a study accepts in its file.
struct StudySchema {
  std::string study;                        ///< The "study" field must equal this.
  std::vector<std::string> approach_kinds;  ///< Allowed "kind" values of approaches.
  std::vector<ParamSpec> approach_params;   ///< Allowed approach "params".
  std::vector<ParamSpec> scenario_params;   ///< Allowed scenario "params".
};

/// Where the plant comes from.
struct PlantSpec {
  /// Form of the plant.
  enum class Kind : std::uint8_t { kFile, kContinuous, kDiscrete };
  Kind kind = Kind::kFile;     ///< Form.
  std::string file;            ///< kFile: a plant description file (lut_gen's format).
  ContinuousModel continuous;  ///< kContinuous: the matrices.
  DiscreteModel discrete;      ///< kDiscrete: the matrices and period.
  /// kContinuous with the design keys (period_us, measurement_covariance, ...): the same
  /// description a plant file with these keys gives (design::parse_plant), else null. kDiscrete
  /// with the design keys (measurement_covariance, Q1c, Q2c, names, actuator or board): the plant
  /// file of form discrete, read with Q1c/Q2c or a board as its exact continuous equivalent
  /// (PlantDescription::from_discrete), else null.
  std::shared_ptr<const design::PlantDescription> design;
};

/// A node's trigger rule.
struct TriggerSpec {
  /// Rule.
  enum class Rule : std::uint8_t { kPeriodic, kSendOnDelta, kMtm };
  Rule rule = Rule::kPeriodic;   ///< Rule.
  std::uint32_t every = 1;       ///< Periodic: every n-th sample.
  std::vector<double> delta;     ///< Send-on-delta: δy per component.
  std::uint32_t time_steps = 0;  ///< Send-on-delta: n_t (0: plain send-on-delta).
  double sigma = 0;              ///< MTM: σ.
  double mtm_delta = 0;          ///< MTM: δ.
  std::uint32_t k_max = 0;       ///< MTM: safety after k_max samples (0: off).
  std::uint32_t k_ref_max = 0;   ///< MTM: send k_ref,max samples after a reference change.
};

/// A node.
struct NodeSpec {
  std::string name;              ///< Unique name.
  std::string role;              ///< "sensor", "controller" or "actuator".
  std::uint8_t address = 0;      ///< Network address (unique).
  std::string mode;              ///< "timer" or "arrival".
  Duration period{0};            ///< Timer period (mode timer; 0 otherwise).
  Duration clock_offset{0};      ///< Its clock reads t + offset.
  std::optional<TriggerSpec> trigger;  ///< Sensors (and event-triggered controllers).
  std::string cpu;               ///< The CPU its job runs on (a declared `cpus[].name`; empty: none).
  /// Its job on that CPU (cpu_task_set.hpp parse_node_job(): external, period and an absent
  /// deadline 0, set by the runner); given exactly when `cpu` is.
  std::optional<cpu::TaskSpec> job;
  bool job_exec = false;         ///< The job's execution time is an `exec` model (not wcet_us/bcet_us).
};

/// A link between two nodes: its own delay/loss models, or a CAN bus identifier.
struct LinkSpec {
  std::string name;       ///< Unique name (names its random streams).
  std::string from;       ///< Sending node.
  std::string to;         ///< Receiving node.
  std::string bus;        ///< CAN bus name (empty: a point-to-point link).
  std::uint32_t id = 0;   ///< CAN identifier (bus only).
  DelayModel delay;       ///< Point-to-point: delay.
  LossModel loss;         ///< Point-to-point: loss.
  bool fifo = false;      ///< Point-to-point: "order": "fifo" (else "any": reordering allowed).
};

/// A CAN bus with optional periodic background traffic.
struct BusSpec {
  CanBusConfig config;                ///< Name, bit rate, identifier length.
  std::vector<CanStream> background;  ///< Other traffic on the bus.
  std::vector<Duration> offsets;      ///< First release of each background stream.
};

/// A set-point signal (the file's "reference", overridable per scenario): a square wave, steps
/// given inline, or steps from a CSV file (two columns t_s,value_volts).
struct ReferenceSpec {
  /// Form of the signal.
  enum class Kind : std::uint8_t { kSquare, kSteps, kFile };
  Kind kind = Kind::kSquare;   ///< Form.
  double amplitude_volts = 0;  ///< kSquare: ±A_r (V, [0, 100]).
  double period_s = 0;         ///< kSquare: T_r (s, [0.001, 10⁶]).
  /// kSteps, kFile: (t_s, value_volts) pairs, times strictly increasing in [0, 10⁶] s, values
  /// finite within ±100 V; the set-point is 0 before the first time, then the value of the last
  /// time reached.
  std::vector<std::pair<double, double>> steps;
  std::vector<std::size_t> lines;  ///< kFile: the file's line of each step (empty otherwise).
  std::string path;            ///< kFile: the CSV file (resolved against the study file's folder).
  std::string field;           ///< Where the file gives it ("reference", "scenarios[i].reference").
  /// One line: "square ±0.2 V, T_r 2 s", "steps (4)", "file x.csv (4 steps)".
  std::string describe() const;
};

/// Most steps a reference may hold (inline or from its file).
inline constexpr std::size_t kMaxReferenceSteps = 100'000;

/// An approach: a name, a study-defined kind, numeric parameters.
struct ApproachSpec {
  std::string name;                       ///< Unique name (table column).
  std::string kind;                       ///< What the study runs.
  std::map<std::string, double> params;   ///< Parameters (schema defaults filled in).
  std::map<std::string, std::string> words;  ///< Word parameters the file gave (ParamSpec::words).
};

/// A scenario: a name, numeric parameters, per-link model overrides.
struct ScenarioSpec {
  std::string name;                          ///< Unique name.
  std::optional<double> duration_s;          ///< Overrides the study's duration.
  std::map<std::string, double> params;      ///< Parameters (schema defaults filled in).
  std::set<std::string> params_given;        ///< Keys of `params` the file gave (the rest are defaults).
  std::optional<ReferenceSpec> reference;    ///< Its own set-point (overrides the file's `reference`).
  std::map<std::string, DelayModel> delays;  ///< Link name → delay override.
  std::map<std::string, LossModel> losses;   ///< Link name → loss override.
};

/// One loop of a file with several (`loops[]`): its plant and the names of its three nodes.
struct LoopSpec {
  std::string name;        ///< Unique name (prefixes its random streams: "<name>/process", ...).
  PlantSpec plant;         ///< Its plant (the same forms as the top-level `plant`).
  std::string sensor;      ///< Its sensor node (role sensor).
  std::string controller;  ///< Its controller node (role controller).
  std::string actuator;    ///< Its actuator node (role actuator).
};

/// A parsed study file.
struct StudyFile {
  std::string source;                   ///< Where it came from.
  std::string study;                    ///< Study code that runs it.
  std::string description;              ///< Free text.
  PlantSpec plant;                      ///< The plant (a file without `loops`).
  /// Several loops in one file (empty: the file is one loop, its plant `plant`). Every node
  /// is in exactly one loop, every link joins two nodes of one loop; `plant` is then unset.
  std::vector<LoopSpec> loops;
  double duration_s = 0;                ///< Simulated time per run.
  std::uint64_t first_seed = 1;         ///< Seed of the first replication.
  std::size_t seeds = 0;                ///< Replications.
  std::vector<NodeSpec> nodes;          ///< Nodes.
  std::vector<LinkSpec> links;          ///< Links.
  std::vector<BusSpec> buses;           ///< CAN buses.
  /// CPUs (the kernel task file's keys: name, scheduler, context_switch_us, background
  /// tasks, isrs; streams per CPU), names unique; node jobs are not among their tasks.
  std::vector<cpu::TaskSet> cpus;
  std::vector<ApproachSpec> approaches; ///< Approaches.
  std::vector<ScenarioSpec> scenarios;  ///< Scenarios.
  std::optional<ReferenceSpec> reference;  ///< The set-point of every scenario without its own.

  /// The node called `name` (InputError otherwise).
  const NodeSpec& node(const std::string& name) const;
  /// The link called `name`, with scenario `s`'s overrides applied (InputError otherwise).
  LinkConfig link_config(const std::string& name, const ScenarioSpec* s = nullptr) const;
};

/// Parses a "reference" object at field `f` (kind square, steps or file; a file's path relative
/// to `base_dir`); InputError naming the field (and the file's line) otherwise.
ReferenceSpec parse_reference(const nlohmann::json& j, const std::string& f, const std::string& base_dir);

/// The steps of a reference CSV file's text: the header "t_s,value_volts", then one
/// "t_s,value_volts" pair per line (blank lines and lines starting with '#' skipped); InputError
/// "field '<field>': <source> line <n>: <reason>" for anything else, non-finite or out-of-range
/// numbers, times not strictly increasing, no steps, more than kMaxReferenceSteps. `lines`
/// (when given) receives the line of each step.
std::vector<std::pair<double, double>> parse_reference_csv(const std::string& text, const std::string& field,
                                                           const std::string& source,
                                                           std::vector<std::size_t>* lines = nullptr);

/// Parses and validates a study file's text; `schema` may be null (any kinds and params).
StudyFile parse_study(const std::string& text, const std::string& source, const StudySchema* schema,
                      const std::string& base_dir = {});

/// Reads, parses and validates a study file (InputError naming the file and field).
StudyFile load_study(const std::string& path, const StudySchema* schema);

}  // namespace oneshot::engine
