/// @file ncs_loop_parts.cpp
/// @brief The parts of a study `ncs` run shared with the live run and the analysis: the plant,
///        the set-point wave, the network legs, the measurement noise factor and the names of
///        counters, links and nodes (see ncs_loop.hpp).
#include <cmath>
#include <string>

#include "ncs_counters.hpp"
#include "ncs_loop.hpp"
#include "oneshot/node/message.hpp"

namespace oneshot::ncs {

engine::ContinuousPlantConfig<kN, kM, kP, 1> plant_config(const Context& ctx, const Scenario& sc, bool noisy) {
  engine::ContinuousPlantConfig<kN, kM, kP, 1> c;
  const design::PlantDescription& p = ctx.plant();
  for (std::size_t i = 0; i < kN; ++i) {
    for (std::size_t j = 0; j < kN; ++j) {
      c.a(i, j) = p.a(i, j);
      c.qc(i, j) = ctx.design().qc(i, j) * sc.noise_scale;
      c.q1c(i, j) = p.q1c(i, j);
    }
    for (std::size_t j = 0; j < kM; ++j) c.b(i, j) = p.b(i, j);
  }
  for (std::size_t i = 0; i < kP; ++i)
    for (std::size_t j = 0; j < kN; ++j) c.c(i, j) = p.c(i, j);
  c.q2c(0, 0) = p.q2c(0, 0);
  c.process_noise = noisy;
  return c;
}

SetpointReference reference(const Context& ctx, const Scenario& sc) {
  const std::size_t out = ctx.design().tracked_outputs.empty() ? 0 : ctx.design().tracked_outputs[0];
  Vector<double, kN> nx;
  Vector<double, kM> nu;
  for (std::size_t i = 0; i < kN; ++i) nx[i] = ctx.design().nx(i, out);
  for (std::size_t j = 0; j < kM; ++j) nu[j] = ctx.design().nu(j, out);
  if (sc.setpoint_changes) return SetpointReference(sc.setpoint_r0, sc.setpoint_changes, nx, nu);
  return SetpointReference(sc.amplitude_volts, static_cast<std::uint32_t>(half_wave_periods(ctx, sc)), nx, nu);
}

engine::LinkConfig leg(const Context& ctx, const Scenario& sc, Approach a, const char* name) {
  engine::LinkConfig c;
  c.name = name;
  c.fifo = true;
  // Frames: k (4) | instant (4) | [τ (4)] | doubles | crc (2) (actuation_sync_messages.hpp, message.hpp).
  const bool report = std::string(name) == "sc" && actuation_synchronized(a);
  c.frame = engine::FrameLayout{0, 4, report ? node::kHeaderBytes + 4 : node::kHeaderBytes, 8, node::kCrcBytes};
  if (delay_free(a)) return c;  // constant 0
  const auto given = sc.legs.find(name);
  if (given != sc.legs.end()) {  // from a study file
    c.delay = given->second.delay;
    c.loss = given->second.loss;
    c.fifo = given->second.fifo;
    return c;
  }
  c.delay.kind = engine::DelayModel::Kind::kUniform;
  c.delay.min = engine::from_us(ctx.timing().leg_min_us);
  c.delay.max = engine::from_us(std::llround(sc.max_delay_ms * 1000));
  c.delay.resolution = engine::from_us(1);
  return c;
}

std::array<double, 3> measurement_cholesky(const Design& d) {
  std::array<double, 3> c{};
  const double r00 = d.r(0, 0);
  c[0] = std::sqrt(r00);
  c[1] = r00 > 0 ? d.r(1, 0) / c[0] : 0;
  c[2] = std::sqrt(std::fmax(0.0, d.r(1, 1) - c[1] * c[1]));
  return c;
}

std::vector<std::string> counter_names(Approach a) {
  if (actuation_synchronized(a)) {
    return concat(concat(sync_sensor_counter_names(), sync_controller_counter_names()), actuator_counter_names());
  }
  return concat(sampling_controller_counter_names(), actuator_counter_names());
}

std::vector<std::string> link_names(Approach a) {
  if (actuation_synchronized(a)) return {"as", "sc", "ca"};
  return {"sc", "ca"};
}

std::vector<std::string> node_names() { return {"sensor", "controller", "actuator"}; }

}  // namespace oneshot::ncs
