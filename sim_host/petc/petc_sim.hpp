/// @file petc_sim.hpp
/// @brief The petc study's closed loop on the engine (numre-petc.md §3–§8): the HDD plant
///        (engine DiscretePlant, 12 states), the sensor's MTM trigger, the controller node
///        (TTS, hold-and-catch-up, or NUMRE + cascade with one of three disturbance
///        estimates), zero-delay links and the actuator's packet buffer; per-run metrics.
///
/// Under a fault spec (FaultRun) the sample and the packet travel as frames through the
/// links "sc" and "ca" and their engine::LinkFaults, and the controller and the actuator check
/// them (petc_frames.hpp); nodes "sensor", "controller", "actuator" may restart (rebuilt as
/// at power-on). Without one (or with an empty spec) the run is the clean run, bit for bit.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "oneshot/engine/fault_spec.hpp"
#include "oneshot/node/disturbance_observer.hpp"
#include "oneshot/node/numre_estimator.hpp"
#include "oneshot/sim/sweep_faults.hpp"
#include "petc_design.hpp"
#include "petc_modal.hpp"

namespace oneshot::sim::petc {

/// Horizon H of the packets (entries H + 1), compiled in: the brief's default h = 200.
inline constexpr std::size_t kHorizon = 200;
/// Sections of the DOB's inverse and its longest delay line, compiled in.
inline constexpr std::size_t kDobSections = 8;
inline constexpr std::size_t kDobMaxDelay = 16;

/// How the controller works in a case.
enum class ControllerKind {
  kTts,    ///< Sensor and controller send every period; e = r − y.
  kHold,   ///< PETC without NUMRE: hold the last y, catch up every period on arrival, send u_k only.
  kNumre,  ///< NUMRE + cascade + packet of H + 1 inputs.
};

/// Which model / disturbance estimate a NUMRE case uses.
enum class ObserverKind {
  kAugmented,  ///< 12-state model with the disturbance states (d̂ = C̄ x̂).
  kDob,        ///< Plant-only NUMRE (d as white input noise) + the DOB substitute.
  kEso,        ///< Plant-only NUMRE + random-walk input-disturbance state.
};

/// One case of §8.
struct CaseSpec {
  std::string name;                               ///< "1" … "6", "6'".
  std::string label;                              ///< Short description.
  ControllerKind controller = ControllerKind::kNumre;  ///< Controller.
  ObserverKind observer = ObserverKind::kAugmented;    ///< Model (NUMRE cases).
  bool noise = false;                             ///< Process noise w (disturbance) and measurement noise v.
  double sigma_s = 0, delta_s = 0;                ///< Sensor MTM thresholds.
  double sigma_c = 0, delta_c = 0;                ///< Controller MTM thresholds.
};

/// The cases 1–6 and 6′ with the brief's thresholds.
std::vector<CaseSpec> default_cases();

/// Options that fix the numbers besides the case and seed.
struct PetcOptions {
  std::string plant_path;           ///< Plant file (default: hdd_numre.json).
  std::size_t steps = 464;          ///< K.
  std::size_t ratio = 2;            ///< MRCI ratio m.
  bool sample_at_update = false;    ///< Slow modes sample e at their own update.
  bool frozen_noise = false;        ///< Printed eq. 13 instead of W_e(N) = Σ.
  double dob_cutoff_hz = 1000;      ///< Q's cutoff.
  double reference = 1;             ///< Unit step at k = 0.
  double sigma_w = -1;              ///< σ_w override (< 0: the plant file's).
  double sigma_v = -1;              ///< σ_v override (< 0: the plant file's).
};

/// Everything a run needs, designed once.
struct PetcSetup {
  PetcOptions opt;                  ///< Options.
  PlantFacts plant;                 ///< Plant (with σ_w, σ_v applied to its model).
  MrciDesign mrci;                  ///< Controller split.
  DobDesign dob;                    ///< DOB substitute.
  BlockDiagonalModel node_model;    ///< Cases 3–5 NUMRE model: the augmented one in its block-diagonal basis.
  EstimatorModel plant_only;        ///< Case 6 NUMRE model.
  EstimatorModel eso;               ///< Case 6′ NUMRE model.
  std::vector<double> var_d;        ///< E[d_k²], k = 0 … K.
  std::vector<double> y_tts;        ///< Case 1's noise-free output (ISE, ISEP reference).
  double ise = 0;                   ///< √Σ (r − y^TTS)².
  double y_range = 0;               ///< Frame checks: |y| ≤ 10 × the peak |y| of case 1 (TTS), or of r.
  double u_range = 0;               ///< Frame checks: |u| ≤ 10 × the peak |u| of case 1 (TTS).
};

/// The link and node names a fault spec of the study may name.
std::vector<std::string> petc_link_names();
/// The nodes that may restart (all three).
std::vector<std::string> petc_node_names();

/// A run under frame faults: the spec in, what happened out.
struct FaultRun {
  engine::FaultSpec spec;       ///< Faults (empty: the clean run, bit for bit).
  sim::RunFaultCounts counts;   ///< Out: injected, refused by cause, stale, estimator resets (ratio_to_clean unset).
  double tracking_error = 0;    ///< Out: √Σ_k (r − y_k)² of the true output (also for a clean run).
  std::uint64_t events = 0;     ///< Out: the kernel's events of the run (queue pops; also for a clean run).
};

/// Designs everything; std::invalid_argument naming what does not fit the compiled sizes.
PetcSetup make_setup(const PetcOptions& opt);

/// The DOB substitute's configuration from the setup's design: Q filter, inverse sections,
/// inverse gain and delay (what ObserverKind::kDob runs, and what its tests drive open loop).
node::DisturbanceObserverConfig<double, kDobSections, kDobMaxDelay> dob_config(const PetcSetup& setup);

/// Per-period traces of one run (optional).
struct RunTrace {
  std::vector<double> y_true, y_meas, u, d, d_hat;   ///< Per period k.
  std::vector<std::uint8_t> sensor_sent, actuator_sent;  ///< Per period k.
  std::vector<std::uint32_t> multiplicity;           ///< Per arrival.
  std::vector<std::vector<double>> x_hat;            ///< x̂(k|k) per arrival (NUMRE cases).
};

/// Names of the per-run metrics, in the order run_case returns them.
const std::vector<std::string>& metric_names();

/// One run of `c` with `seed`; one value per metric_names() entry.
/// `faults` (optional): the run's frame faults and their counters.
std::vector<double> run_case(const PetcSetup& setup, const CaseSpec& c, std::uint64_t seed, RunTrace* trace = nullptr,
                             FaultRun* faults = nullptr);

}  // namespace oneshot::sim::petc
