/// @file sod_model.cpp
/// @brief Loading the send-on-delta plant (see sod_model.hpp).
#include "sod_model.hpp"

#include <stdexcept>

#include "oneshot/design/plant_description.hpp"
#include "oneshot/design/sampled_model.hpp"

namespace oneshot::sod {

std::string default_sod_plant_path() { return ONESHOT_STUDY_PLANT_FILE; }

SodModel load_sod_model(const std::string& path) {
  const design::PlantDescription plant = design::load_plant_file(path);
  if (plant.n() != kStates || plant.m() != kInputs || plant.p() != kNodes || plant.q() != 0) {
    throw std::invalid_argument(path + ": study 'sod' needs n = 2, m = 1, p = 2 and no disturbance input; plant has n = " +
                                std::to_string(plant.n()) + ", m = " + std::to_string(plant.m()) +
                                ", p = " + std::to_string(plant.p()) + ", q = " + std::to_string(plant.q()));
  }
  const design::DenseMatrix& r = plant.measurement_covariance;
  if (r(0, 1) != 0.0 || r(1, 0) != 0.0) {
    throw std::invalid_argument(path + ": field 'noise.measurement_covariance' must be diagonal for study 'sod' "
                                       "(independent sensor nodes, one scalar correction each)");
  }
  const design::SampledModel s = design::sample_plant(plant);
  SodModel m;
  m.plant_name = plant.name;
  m.plant_source = path;
  m.period_us = plant.period_us;
  for (std::size_t i = 0; i < kStates; ++i) {
    for (std::size_t j = 0; j < kStates; ++j) {
      m.a_d(i, j) = s.phi(i, j);
      m.q_d(i, j) = s.qd(i, j);
    }
    m.b_d(i, 0) = s.gamma(i, 0);
  }
  for (std::size_t i = 0; i < kNodes; ++i) {
    for (std::size_t j = 0; j < kStates; ++j) m.c(i, j) = plant.c(i, j);
    m.r_diag[i] = r(i, i);
  }
  m.phi = s.phi;
  m.qd = s.qd;
  m.cm = plant.c;
  m.discrete = {s.phi, s.gamma, {}, plant.c, s.qd, {}, {}, engine::from_us(plant.period_us)};
  return m;
}

}  // namespace oneshot::sod
