/// @file dropping_plant.cpp
/// @brief The dropping study's plant and arrival law (see dropping_plant.hpp).
#include "dropping_plant.hpp"

#include <cmath>
#include <stdexcept>

#include "oneshot/design/spectrum.hpp"
#include "oneshot/util/file_io.hpp"

#ifndef ONESHOT_STUDY_PLANT_FILE
#error "ONESHOT_STUDY_PLANT_FILE must name lut_gen/plants/sinopoli_dropping.json (oneshot_study PLANT ... FOR)"
#endif

namespace oneshot::dropping {
namespace {

template <std::size_t R, std::size_t C>
Matrix<double, R, C> fixed(const design::DenseMatrix& m, const char* what, const std::string& source) {
  if (m.rows != R || m.cols != C)
    throw std::runtime_error(source + ": " + what + " is " + std::to_string(m.rows) + "x" + std::to_string(m.cols) +
                             ", the dropping study needs " + std::to_string(R) + "x" + std::to_string(C));
  Matrix<double, R, C> out;
  for (std::size_t i = 0; i < R; ++i)
    for (std::size_t j = 0; j < C; ++j) out(i, j) = m(i, j);
  return out;
}

}  // namespace

const std::string& dropping_plant_json() {
  static const std::string text = util::read_text_file(ONESHOT_STUDY_PLANT_FILE, "plant file");
  return text;
}

DroppingPlant load_dropping_plant(const std::string& path) {
  DroppingPlant d;
  d.plant = path.empty() ? design::parse_plant(dropping_plant_json(), "built-in sinopoli_dropping.json")
                         : design::load_plant_file(path);
  const std::string& src = d.plant.source;
  if (d.plant.form == design::PlantForm::kContinuous)
    throw std::runtime_error(src + ": the dropping study needs a discrete plant (Phi, Gamma per step)");
  if (d.plant.n() != kN || d.plant.m() != kM || d.plant.p() != kP)
    throw std::runtime_error(src + ": plant has n = " + std::to_string(d.plant.n()) + ", m = " +
                             std::to_string(d.plant.m()) + ", p = " + std::to_string(d.plant.p()) +
                             "; the dropping study expects n = 3, m = 1, p = 1");
  d.design = design::synthesize(d.plant);
  if (!d.design.lqr_available) throw std::runtime_error(src + ": no LQR gain: " + d.design.lqr_unavailable_reason);
  d.phi = fixed<kN, kN>(d.design.phi_h, "Phi", src);
  d.gamma = fixed<kN, kM>(d.design.gamma_h, "Gamma", src);
  d.c = fixed<kP, kN>(d.plant.c, "C", src);
  d.q = fixed<kN, kN>(d.design.q_constant, "Q", src);
  d.r = fixed<kP, kP>(d.design.r, "R", src);
  d.p0 = fixed<kN, kN>(d.design.p0, "P0", src);
  d.l = fixed<kM, kN>(d.design.l, "L", src);
  d.q1 = fixed<kN, kN>(d.design.q1, "Q1", src);
  d.q2 = fixed<kM, kM>(d.design.q2, "Q2", src);
  d.rho = design::spectral_radius(d.design.phi_h);
  d.lambda_sys = lambda_sys_from_radius(d.rho);
  return d;
}

double poisson_pmf(int t, double mean) {
  if (t < 0) return 0;
  // e^{−D} D^t / t! in logs (no overflow for large t).
  return std::exp(-mean + t * std::log(mean) - std::lgamma(t + 1.0));
}

double arrival_probability(int t_hold, double mean_delay_periods, double loss) {
  if (t_hold < 1) throw std::invalid_argument("T_hold must be at least 1");
  if (!(mean_delay_periods > 0) || !(loss >= 0 && loss < 1))
    throw std::invalid_argument("arrival probability needs D > 0 and 0 <= loss < 1");
  double s = 0;
  for (int t = 0; t < t_hold; ++t) s += poisson_pmf(t, mean_delay_periods);
  return (1 - loss) * s;
}

double delay_for_lambda(double lambda, double loss) {
  if (!(lambda > 0) || !(lambda < 1 - loss))
    throw std::invalid_argument("lambda must lie in (0, 1 - loss) for a Poisson delay with T_hold = 1");
  return -std::log(lambda / (1 - loss));
}

}  // namespace oneshot::dropping
