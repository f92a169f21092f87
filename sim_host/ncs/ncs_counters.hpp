/// @file ncs_counters.hpp
/// @brief The node counters a run of study `ncs` reports (engine and live): refusals and
///        drops per node, by name ("sensor.stale", …), in a fixed order per loop kind.
///
/// The one place that reads the nodes' statistics for the fault table and the live
/// summary: when the nodes get more causes (non-finite, out of range, unexpected source,
/// sequence window, re-acquisitions), add them here, names and values side by side.
#pragma once

#include <string>
#include <vector>

namespace oneshot::ncs {

/// Counter names of the actuation-synchronized loops (A, AK, AKx, AKl).
inline const std::vector<std::string>& sync_counter_names() {
  static const std::vector<std::string> names = {
      "sensor.malformed",   "sensor.stale",    "controller.malformed", "controller.stale",
      "controller.faults",  "actuator.malformed", "actuator.stale",    "actuator.late"};
  return names;
}

/// Counter values of a synchronized loop's nodes, in sync_counter_names() order.
template <typename Sensor, typename Controller, typename Actuator>
std::vector<double> sync_counters(const Sensor& s, const Controller& c, const Actuator& a) {
  return {double(s.statistics().malformed), double(s.statistics().stale),    double(c.statistics().malformed),
          double(c.statistics().stale),     double(c.statistics().faults),   double(a.statistics().malformed),
          double(a.statistics().stale),     double(a.statistics().late)};
}

/// Counter names of the sampling-synchronized loops (I, S, SK, S+, IK).
inline const std::vector<std::string>& sampling_counter_names() {
  static const std::vector<std::string> names = {"controller.malformed", "controller.stale", "actuator.malformed",
                                                 "actuator.stale"};
  return names;
}

/// Counter values of a sampling loop's nodes, in sampling_counter_names() order.
template <typename Controller, typename Actuator>
std::vector<double> sampling_counters(const Controller& c, const Actuator& a) {
  return {double(c.statistics().malformed), double(c.statistics().stale), double(a.statistics().malformed),
          double(a.statistics().stale)};
}

}  // namespace oneshot::ncs
