/// @file study_ncs_runner.hpp
/// @brief A study file with "study": "ncs" mapped onto study ncs's loop (sim_host/ncs/): the
///        schema it accepts, what it refuses at check time (naming the field), and the
///        approaches and scenarios of its sweep.
///
/// The ncs loop has three firmware nodes (sensor, controller, actuator), three point-to-point
/// legs "as" (actuator → sensor), "sc", "ca" and the plant of a plant file, or the same plant
/// written inline (plant.continuous with the plant file's design keys). A file maps onto
/// it when it declares exactly that: the legs' delay, loss and order come from the file (and
/// the scenarios' link overrides), the scenario parameters are ncs Scenario fields, the
/// approach kinds are ncs approach names. Legs sc and ca may run on a CAN bus (with the bus's
/// background traffic) under the sampling loops (I, S, SK, IK): the actuation-synchronized
/// approaches and S+ are refused then, as is the leg as on a bus. The set-point is the
/// scenario's or the file's `reference` (square, steps, file), else the params' square wave; the
/// one-shot loops' sensor may run send-on-delta or MTM, the one-shot controller's timer takes a
/// phase, in a file with several loops (`loops[]`) a loop's sensor phase (its
/// `clock_offset_us`) is mapped, and in a file of one loop without one-shot approaches or CPUs
/// every node's `clock_offset_us` φ, 0 ≤ φ < h (ncs::Scenario::sensor_clock_us: its clock reads
/// t − φ). Everything else the schema accepts (other clock offsets, other
/// trigger rules, other addresses, other plant shapes, discrete plants) is refused with the field
/// and the reason. The plant's mapping (plant file or inline plant) is study_plant_map.hpp's.
#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "ncs_live.hpp"
#include "ncs_model.hpp"
#include "oneshot/engine/study_file.hpp"
#include "study_one_shot_discretizer.hpp"
#include "study_plant_map.hpp"

namespace oneshot::study {

/// A leg of the ncs loop: its name (the link's in the file, and its random streams'
/// `link/<name>/…`) and the roles of the nodes it leaves and reaches.
struct NcsLeg {
  const char* name;  ///< "as", "sc" or "ca".
  const char* from;  ///< Role of the sending node.
  const char* to;    ///< Role of the receiving node.
};

/// The legs of the ncs loop, the one table of their roles.
inline constexpr NcsLeg kNcsLegs[] = {
    {"as", "actuator", "sensor"}, {"sc", "sensor", "controller"}, {"ca", "controller", "actuator"}};

/// The leg named `name`; nullptr when the loop has none of that name.
const NcsLeg* find_ncs_leg(const std::string& name);

/// What `study run` accepts from a file with "study": "ncs" (approach kinds: the ncs
/// approaches; approach param `discretizer`, a word: generic, table, nearest (the one-shot
/// approaches only, map_ncs_study() checks); scenario params amplitude_volts, period_s —
/// required by map_ncs_study() unless a `reference` gives the set-point —, noise_scale default 1).
const engine::StudySchema& ncs_schema();

/// A study file resolved onto the ncs loop.
struct NcsStudy {
  std::string source;                         ///< The study file.
  std::string plant_path;                     ///< The plant file (resolved against the study file's folder; "" inline).
  std::shared_ptr<const ncs::Context> ctx;    ///< Plant and design.
  std::vector<ncs::Approach> approaches;      ///< In file order (I first).
  /// Per approach (file order): the one-shot filter's discretizer (`params.discretizer`,
  /// generic for the other approaches); its triple is in every scenario's one_shot_triples.
  std::vector<OneShotDiscretization> discretizations;
  std::vector<ncs::Scenario> scenarios;       ///< In file order, legs from the file.
  std::vector<std::string> links;             ///< Leg names the file declares ("as", "sc", "ca" in file order).
  /// Per scenario (file order), per leg on a CAN bus: the worst-case response time of its
  /// message from `study check`'s analysis in µs (nullopt: unbounded); attach_bus_bounds().
  std::vector<std::map<std::string, std::optional<double>>> bus_response_us;
  std::uint64_t first_seed = 1;               ///< Seed of the first replication.
  std::size_t seeds = 0;                      ///< Replications.
  /// A file with several loops (`loops[]`): this loop's name (its random streams' prefix
  /// "<loop>/"); "" for the one loop of a file without.
  std::string loop;
  /// Its nodes' addresses in the run: sensor, controller, actuator.
  std::array<std::uint8_t, 3> addresses{ncs::kLiveSensor, ncs::kLiveController, ncs::kLiveActuator};
  /// A file with several loops: this loop's phase φ, its sensor's `clock_offset_us` (its timer
  /// at kh + φ, 0 ≤ φ < h; ncs::LoopOnBus::clock_offset_us); 0 without `loops`.
  std::int64_t clock_offset_us = 0;
  /// Leg name ("sc", "ca", "as") → the file's link name (the same name without `loops`).
  std::map<std::string, std::string> link_names;
  /// A file with several loops: every loop mapped (file order; this study's own fields are the
  /// first loop's). Empty for a file without `loops`.
  std::vector<NcsStudy> loops;
};

/// A file with several loops (`loops[]`) mapped loop by loop (study_loops_map.cpp): each loop's
/// view (loop_view(), addresses 1, 2, 3, links named by the leg they are) through
/// map_ncs_study(), refusals named in the file's fields (`nodes[i]`, `links[i]`,
/// `loops[i].plant`, `loops[i]`); the sampling approaches I, S, SK, IK only, no CPUs. The result
/// is the first loop's study with every loop in NcsStudy::loops.
NcsStudy map_ncs_loops(const engine::StudyFile& file);

/// Loop `i` of a file with several loops as a file of its own: its plant, its three nodes,
/// the links between them (names kept), the file's buses, approaches and scenarios (their
/// overrides of the loop's links only); no `loops`, no CPUs.
engine::StudyFile loop_view(const engine::StudyFile& file, std::size_t i);

/// Maps a file parsed with ncs_schema() onto the ncs loop; engine::InputError naming the
/// file and the field for anything the loop cannot run, and for a scenario on which the
/// reference approach would cost 0 (I, or IK without noise, when the set-point never changes or
/// the run ends before its first change): every ratio to it would divide by 0. With IK leading
/// (plants of n > 6) and noise, such a scenario runs (a regulation study).
NcsStudy map_ncs_study(const engine::StudyFile& file);

/// Caps the simulated time of every scenario of `s` at `max_s` seconds (`study run
/// --max-duration`, the fuzz harness); longer runs are cut there, shorter ones stay.
/// engine::InputError naming `field` when `max_s` is not finite, below one period h, or
/// before a scenario's first set-point switch when the reference approach would then cost 0
/// (I; IK without noise).
/// `s` is unchanged when refused.
void cap_duration(NcsStudy& s, double max_s, const std::string& field);

}  // namespace oneshot::study
