/// @file ncs_counters.hpp
/// @brief The node counters a run of study `ncs` reports (engine and live): refusals and
///        drops per node, by name ("sensor.stale", …), in a fixed order per node.
///
/// The one place that reads the nodes' statistics for the fault table and the live
/// summary: decode failures, drops and the refusal causes of node::FrameRefusals
/// (docs/faults.md), names and values side by side.
#pragma once

#include <string>
#include <vector>

namespace oneshot::ncs {

/// `names` followed by the refusal causes every decoding node counts (node::FrameRefusals)
/// after `node.`: CRC mismatch (bits altered on the way), non-finite payload, value outside the design's range, unexpected source,
/// sequence/stamp outside the window, re-acquisitions of a restarted peer.
inline std::vector<std::string> with_refusal_names(std::vector<std::string> names, const std::string& node) {
  for (const char* c : {".corrupt", ".refused_non_finite", ".refused_out_of_range", ".refused_source", ".refused_sequence", ".reacquired"})
    names.push_back(node + c);
  return names;
}
/// `values` followed by the refusal counters of `s`, in the order of with_refusal_names().
template <typename Stats>
std::vector<double> with_refusals(std::vector<double> values, const Stats& s) {
  values.insert(values.end(), {double(s.corrupt), double(s.refused_non_finite), double(s.refused_out_of_range), double(s.refused_source),
                               double(s.refused_sequence), double(s.reacquired)});
  return values;
}

/// Counter names of the synchronized sensor.
inline std::vector<std::string> sync_sensor_counter_names() {
  return with_refusal_names({"sensor.malformed", "sensor.stale"}, "sensor");
}
/// Their values, in that order.
template <typename Sensor>
std::vector<double> sync_sensor_counters(const Sensor& s) {
  const auto& st = s.statistics();
  return with_refusals({double(st.malformed), double(st.stale)}, st);
}

/// Counter names of the synchronized controller (estimator resets: the estimate turned
/// non-finite and was reset; withheld: a non-finite command was not sent; filled: periods
/// without a report predicted over).
inline std::vector<std::string> sync_controller_counter_names() {
  return with_refusal_names({"controller.malformed", "controller.stale", "controller.faults", "controller.estimator_resets",
                             "controller.withheld", "controller.filled"},
                            "controller");
}
/// Their values, in that order.
template <typename Controller>
std::vector<double> sync_controller_counters(const Controller& c) {
  const auto& st = c.statistics();
  return with_refusals({double(st.malformed), double(st.stale), double(st.faults), double(st.estimator_resets),
                        double(st.withheld), double(st.filled)},
                       st);
}

/// Counter names of an actuator (synchronized or not).
inline std::vector<std::string> actuator_counter_names() {
  return with_refusal_names({"actuator.malformed", "actuator.stale", "actuator.late"}, "actuator");
}
/// Their values, in that order.
template <typename Actuator>
std::vector<double> actuator_counters(const Actuator& a) {
  const auto& st = a.statistics();
  return with_refusals({double(st.malformed), double(st.stale), double(st.late)}, st);
}

/// Counter names of a sampling loop's controller (withheld: a non-finite command not sent).
inline std::vector<std::string> sampling_controller_counter_names() {
  return with_refusal_names({"controller.malformed", "controller.stale", "controller.withheld"}, "controller");
}
/// Their values, in that order.
template <typename Controller>
std::vector<double> sampling_controller_counters(const Controller& c) {
  const auto& st = c.statistics();
  return with_refusals({double(st.malformed), double(st.stale), double(st.withheld)}, st);
}

/// a followed by b.
template <typename T>
std::vector<T> concat(std::vector<T> a, const std::vector<T>& b) {
  a.insert(a.end(), b.begin(), b.end());
  return a;
}

}  // namespace oneshot::ncs
