/// @file sync_test_loop.hpp
/// @brief The actuation-synchronized controller the node tests build on the generated
///        reference plant (types and node addresses), shared by the validation and gap tests.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "oneshot/generated/plant_tables.hpp"
#include "oneshot/host/host_network.hpp"
#include "oneshot/node/sync_controller_node.hpp"
#include "oneshot/node/sync_estimators.hpp"
#include "oneshot/table_discretizer.hpp"

namespace oneshot::node::sync_test {

using K = generated::PlantConstants<double>;                                  ///< The generated plant.
using Structure = generated::PlantStructure;                                  ///< Its dimensions.
using Disc = TableDiscretizer<K::Format, Structure, double>;                  ///< Its Φ, Γ tables.
using Est = HalfKalmanEstimator<K::Format, Structure, Disc>;                  ///< AK's estimator.
using Ref = SquareWaveReference<double, 2, 1>;                                ///< The reference.
using Ctrl = SyncControllerNode<host::HostNetwork, Est, Ref, double, 2, 1, 1>;  ///< The controller.
inline constexpr std::uint8_t kSensor = 1;      ///< Sensor's address.
inline constexpr std::uint8_t kController = 2;  ///< Controller's address.
inline constexpr std::uint8_t kActuator = 3;    ///< Actuator's address.

/// Puts the sensor's report (k, t_s, τ, y, echo u), sent by `from`, into the controller's
/// interface `net` (handled at its next on_receive()).
inline void deliver_report(host::HostNetworkState& net, std::uint8_t from, SequenceNumber k, McuInstant t_s,
                           std::int32_t tau_us, double y, double u) {
  SampleReport<double, 1, 1> r;
  r.k = k;
  r.t_s = t_s;
  r.tau_us = tau_us;
  r.y[0] = y;
  r.u_applied[0] = u;
  std::uint8_t bytes[kMaxMessageBytes];
  const std::size_t n = encode(r, bytes);
  net.deliver(host::Frame{from, kController, std::vector<std::uint8_t>(bytes, bytes + n)});
}

}  // namespace oneshot::node::sync_test
