/// @file petc_exectime.hpp
/// @brief Instruction counts of one NUMRE arrival of the petc controller node on the
///        Cortex-M4F image under QEMU (insn_window plugin), beside the node's multiply-add
///        counter, and the same arrivals on the host build of the node in float (and double).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "petc_sim.hpp"

namespace oneshot::sim::petc {

/// Options of `petc exectime`.
struct ExectimeOptions {
  std::string case_name = "4";         ///< Case whose measurements give y (3, 4, 5).
  std::uint64_t seed = 1;              ///< Seed of that trace.
  std::vector<std::uint32_t> extra;    ///< More multiplicities to measure (besides 1, median, max).
  std::string firmware_dir;            ///< Build tree holding firmware-cortex-m4f/ (empty: this build's).
  std::string plugin_path;             ///< insn_window plugin (empty: this build's).
};

/// Multiplicities of one case's arrivals (N ≥ 1).
struct CaseMultiplicity {
  std::string name;            ///< Case.
  std::size_t arrivals = 0;    ///< Arrivals with N ≥ 1.
  std::uint32_t median = 0;    ///< Median N.
  std::uint32_t max = 0;       ///< Largest N.
};

/// The host's half: the multiplicities, the arrivals and the results of the same node code in
/// float and double (no QEMU). Used by run_exectime and the tests.
struct ArrivalPlan {
  std::vector<std::uint32_t> k;            ///< Arrival periods (k[0] = 0: the first arrival, N = 0).
  std::vector<float> y;                    ///< Measurement at each arrival (the case's trace).
  std::uint32_t n_typical = 0;             ///< Median N over the arrivals of cases 3, 4, 5.
  std::uint32_t n_mean = 0;                ///< Mean N over them (periods per arrival), rounded.
  std::uint32_t n_max = 0;                 ///< Largest N over them.
  std::vector<CaseMultiplicity> per_case;  ///< The same per case.
  std::vector<std::uint32_t> words;        ///< The node's constants (IEEE single bits, petc_pil.hpp layout).
};

/// Multiplicities 1, the median, the mean and the largest of cases 3–5 (+ extra), ascending, and
/// the arrival sequence that realizes them; std::invalid_argument for an unknown case or a
/// sequence longer than the run.
ArrivalPlan plan_arrivals(const PetcSetup& setup, const ExectimeOptions& opt);

/// The host results of one arrival (float node).
struct HostArrival {
  std::uint32_t cause = 0;                 ///< SendCause.
  std::uint32_t multiplicity = 0;          ///< N.
  std::uint64_t macs = 0;                  ///< Multiply-adds of the arrival.
  std::vector<float> x_hat;                ///< x̂(k|k).
  std::vector<float> cascade, d_hat;       ///< The H + 1 inputs and their d̂.
  double max_rel_diff_double = 0;          ///< max |u_float − u_double| / max |u_double| over the cascade.
};

/// Runs the plan on the host build of the node (float, and double for the precision figure).
std::vector<HostArrival> host_arrivals(const PetcSetup& setup, const ArrivalPlan& plan);

/// `petc exectime`: the plan on the M4F image (PilError when the image or QEMU is missing),
/// instructions per arrival by N, multiply-adds, ratio, bit-identity with the host, flash, RAM, stack.
nlohmann::json run_exectime(const PetcSetup& setup, const ExectimeOptions& opt);

/// Markdown table of run_exectime's JSON.
std::string exectime_markdown(const nlohmann::json& j);

}  // namespace oneshot::sim::petc
