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

/// Names of the refusal causes every decoding node counts (node::FrameRefusals), after
/// `node.`: non-finite payload, value outside the design's range, unexpected source,
/// sequence/stamp outside the window, re-acquisitions of a restarted peer.
inline std::vector<std::string> refusal_counter_names(const std::string& node) {
  return {node + ".refused_non_finite", node + ".refused_out_of_range", node + ".refused_source",
          node + ".refused_sequence", node + ".reacquired"};
}
/// Their values, in that order.
template <typename Stats>
std::vector<double> refusal_counters(const Stats& s) {
  return {double(s.refused_non_finite), double(s.refused_out_of_range), double(s.refused_source),
          double(s.refused_sequence), double(s.reacquired)};
}

/// Counter names of the synchronized sensor.
inline std::vector<std::string> sync_sensor_counter_names() {
  std::vector<std::string> n{"sensor.malformed", "sensor.stale"};
  const auto r = refusal_counter_names("sensor");
  n.insert(n.end(), r.begin(), r.end());
  return n;
}
/// Their values, in that order.
template <typename Sensor>
std::vector<double> sync_sensor_counters(const Sensor& s) {
  const auto& st = s.statistics();
  std::vector<double> v{double(st.malformed), double(st.stale)};
  const auto r = refusal_counters(st);
  v.insert(v.end(), r.begin(), r.end());
  return v;
}

/// Counter names of the synchronized controller (estimator resets: the estimate turned
/// non-finite and was reset; withheld: a non-finite command was not sent; filled: periods
/// without a report predicted over).
inline std::vector<std::string> sync_controller_counter_names() {
  std::vector<std::string> n{"controller.malformed", "controller.stale", "controller.faults",
                             "controller.estimator_resets", "controller.withheld", "controller.filled"};
  const auto r = refusal_counter_names("controller");
  n.insert(n.end(), r.begin(), r.end());
  return n;
}
/// Their values, in that order.
template <typename Controller>
std::vector<double> sync_controller_counters(const Controller& c) {
  const auto& st = c.statistics();
  std::vector<double> v{double(st.malformed), double(st.stale), double(st.faults), double(st.estimator_resets),
                        double(st.withheld), double(st.filled)};
  const auto r = refusal_counters(st);
  v.insert(v.end(), r.begin(), r.end());
  return v;
}

/// Counter names of an actuator (synchronized or not).
inline std::vector<std::string> actuator_counter_names() {
  std::vector<std::string> n{"actuator.malformed", "actuator.stale", "actuator.late"};
  const auto r = refusal_counter_names("actuator");
  n.insert(n.end(), r.begin(), r.end());
  return n;
}
/// Their values, in that order.
template <typename Actuator>
std::vector<double> actuator_counters(const Actuator& a) {
  const auto& st = a.statistics();
  std::vector<double> v{double(st.malformed), double(st.stale), double(st.late)};
  const auto r = refusal_counters(st);
  v.insert(v.end(), r.begin(), r.end());
  return v;
}

/// Counter names of a sampling loop's controller (withheld: a non-finite command not sent).
inline std::vector<std::string> sampling_controller_counter_names() {
  std::vector<std::string> n{"controller.malformed", "controller.stale", "controller.withheld"};
  const auto r = refusal_counter_names("controller");
  n.insert(n.end(), r.begin(), r.end());
  return n;
}
/// Their values, in that order.
template <typename Controller>
std::vector<double> sampling_controller_counters(const Controller& c) {
  const auto& st = c.statistics();
  std::vector<double> v{double(st.malformed), double(st.stale), double(st.withheld)};
  const auto r = refusal_counters(st);
  v.insert(v.end(), r.begin(), r.end());
  return v;
}

/// a followed by b.
template <typename T>
std::vector<T> concat(std::vector<T> a, const std::vector<T>& b) {
  a.insert(a.end(), b.begin(), b.end());
  return a;
}

}  // namespace oneshot::ncs
