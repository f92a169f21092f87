/// @file ncs_counters.hpp
/// @brief The node counters a run of study `ncs` reports (engine and live): refusals and
///        drops per node, by name ("sensor.stale", …), in a fixed order per node.
///
/// The one place that reads the nodes' statistics for the fault table and the live
/// summary: when the nodes get more causes (non-finite, out of range, unexpected source,
/// sequence window, re-acquisitions), add them here, names and values side by side.
#pragma once

#include <string>
#include <vector>

namespace oneshot::ncs {

/// Counter names of the synchronized sensor.
inline std::vector<std::string> sync_sensor_counter_names() { return {"sensor.malformed", "sensor.stale"}; }
/// Their values, in that order.
template <typename Sensor>
std::vector<double> sync_sensor_counters(const Sensor& s) {
  return {double(s.statistics().malformed), double(s.statistics().stale)};
}

/// Counter names of the synchronized controller.
inline std::vector<std::string> sync_controller_counter_names() {
  return {"controller.malformed", "controller.stale", "controller.faults"};
}
/// Their values, in that order.
template <typename Controller>
std::vector<double> sync_controller_counters(const Controller& c) {
  return {double(c.statistics().malformed), double(c.statistics().stale), double(c.statistics().faults)};
}

/// Counter names of an actuator (synchronized or not).
inline std::vector<std::string> actuator_counter_names() { return {"actuator.malformed", "actuator.stale", "actuator.late"}; }
/// Their values, in that order.
template <typename Actuator>
std::vector<double> actuator_counters(const Actuator& a) {
  return {double(a.statistics().malformed), double(a.statistics().stale), double(a.statistics().late)};
}

/// Counter names of a sampling loop's controller.
inline std::vector<std::string> sampling_controller_counter_names() { return {"controller.malformed", "controller.stale"}; }
/// Their values, in that order.
template <typename Controller>
std::vector<double> sampling_controller_counters(const Controller& c) {
  return {double(c.statistics().malformed), double(c.statistics().stale)};
}

/// a followed by b.
template <typename T>
std::vector<T> concat(std::vector<T> a, const std::vector<T>& b) {
  a.insert(a.end(), b.begin(), b.end());
  return a;
}

}  // namespace oneshot::ncs
