/// @file ncs_loop_parts.cpp
/// @brief The parts of a study `ncs` run shared with the live run and the analysis: the plant,
///        the set-point wave, the network legs, the measurement noise factor and the names of
///        counters, links and nodes (see ncs_loop.hpp).
#include <cmath>
#include <string>
#include <stdexcept>

#include "ncs_counters.hpp"
#include "ncs_loop.hpp"
#include "oneshot/engine/psd_math.hpp"
#include "oneshot/node/message.hpp"

namespace oneshot::ncs {

template <typename S>
engine::ContinuousPlantConfig<S::n, S::m, S::p, 1> plant_config_of(const Context& ctx, const Scenario& sc, bool noisy) {
  engine::ContinuousPlantConfig<S::n, S::m, S::p, 1> c;
  const design::PlantDescription& p = ctx.plant();
  const std::size_t n = p.a.rows, m = p.b.cols, q = p.c.rows;
  if (n > S::n || m > S::m || q > S::p || p.q1c.rows != n || p.q2c.rows != m) {
    throw std::logic_error("ncs: the plant's shape or cost does not fit the loop's (" + std::to_string(n) + ", " + std::to_string(m) +
                           ", " + std::to_string(q) + ")");
  }
  // Embedded in a larger shape: A, B, C, Q_c, Q1c, Q2c zero padded (the padded states stay at 0).
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = 0; j < n; ++j) {
      c.a(i, j) = p.a(i, j);
      c.qc(i, j) = ctx.design().qc(i, j) * sc.noise_scale;
      c.q1c(i, j) = p.q1c(i, j);
    }
    for (std::size_t j = 0; j < m; ++j) c.b(i, j) = p.b(i, j);
  }
  for (std::size_t i = 0; i < q; ++i)
    for (std::size_t j = 0; j < n; ++j) c.c(i, j) = p.c(i, j);
  for (std::size_t i = 0; i < m; ++i)
    for (std::size_t j = 0; j < m; ++j) c.q2c(i, j) = p.q2c(i, j);
  c.process_noise = noisy;
  c.active_states = n;  // the normals of the real states only: the padded run draws the plant's own numbers
  return c;
}

template <typename S>
BasicSetpointReference<S::n, S::m> reference_of(const Context& ctx, const Scenario& sc) {
  const std::size_t out = ctx.design().tracked_outputs.empty() ? 0 : ctx.design().tracked_outputs[0];
  Vector<double, S::n> nx;  // 0 on the padded states and inputs
  Vector<double, S::m> nu;
  for (std::size_t i = 0; i < ctx.states(); ++i) nx[i] = ctx.design().nx(i, out);
  for (std::size_t j = 0; j < ctx.inputs(); ++j) nu[j] = ctx.design().nu(j, out);
  if (sc.setpoint_changes) return BasicSetpointReference<S::n, S::m>(sc.setpoint_r0, sc.setpoint_changes, nx, nu);
  return BasicSetpointReference<S::n, S::m>(sc.amplitude_volts, static_cast<std::uint32_t>(half_wave_periods(ctx, sc)), nx, nu);
}

#define ONESHOT_NCS_PARTS_OF(n, m, p)                                                                                \
  template engine::ContinuousPlantConfig<n, m, p, 1> plant_config_of<Shape<n, m, p>>(const Context&, const Scenario&, bool); \
  template BasicSetpointReference<n, m> reference_of<Shape<n, m, p>>(const Context&, const Scenario&);
ONESHOT_NCS_SHAPES(ONESHOT_NCS_PARTS_OF)
#undef ONESHOT_NCS_PARTS_OF

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
  const Matrix<double, kP, kP> l = engine::psd_cholesky<kP>(d.r);
  return {l(0, 0), l(1, 0), l(1, 1)};
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
