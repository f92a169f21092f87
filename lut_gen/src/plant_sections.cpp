/// @file plant_sections.cpp
/// @brief Realization of transfer-function sections (see plant_sections.hpp).
#include "oneshot/design/plant_sections.hpp"

#include <cmath>
#include <initializer_list>
#include <stdexcept>

#include "oneshot/design/dense_ops.hpp"

namespace oneshot::design {
namespace {

constexpr double kPi = 3.14159265358979323846;

/// A single-input single-output discrete or continuous state space (A, B, C, D).
struct StateSpace {
  DenseMatrix a, b, c, d;
};

/// first → second in series: x = [x₁; x₂],
/// A = [[A₁, 0], [B₂C₁, A₂]], B = [B₁; B₂D₁], C = [D₂C₁, C₂], D = D₂D₁.
StateSpace series(const StateSpace& first, const StateSpace& second) {
  const std::size_t n1 = first.a.rows;
  const std::size_t n2 = second.a.rows;
  if (n1 == 0) {
    StateSpace s = second;
    s.b = second.b * first.d(0, 0);
    s.d = second.d * first.d(0, 0);
    return s;
  }
  StateSpace s;
  s.a = DenseMatrix::zeros(n1 + n2, n1 + n2);
  set_block(s.a, 0, 0, first.a);
  set_block(s.a, n1, 0, second.b * first.c);
  set_block(s.a, n1, n1, second.a);
  s.b = DenseMatrix::zeros(n1 + n2, 1);
  set_block(s.b, 0, 0, first.b);
  set_block(s.b, n1, 0, second.b * first.d);
  s.c = DenseMatrix::zeros(1, n1 + n2);
  set_block(s.c, 0, 0, second.d * first.c);
  set_block(s.c, 0, n1, second.c);
  s.d = second.d * first.d;
  return s;
}

/// Φ = e^{AT}, Γ = ∫₀ᵀ e^{As} ds B from one exponential of [[A, B], [0, 0]]·T.
void zoh(const DenseMatrix& a, const DenseMatrix& b, double t, DenseMatrix& phi, DenseMatrix& gamma,
         const std::string& what) {
  const std::size_t n = a.rows;
  const std::size_t m = b.cols;
  DenseMatrix blk = DenseMatrix::zeros(n + m, n + m);
  set_block(blk, 0, 0, a * t);
  set_block(blk, 0, n, b * t);
  const DenseMatrix e = expm(blk, what);
  phi = block(e, 0, 0, n, n);
  gamma = block(e, 0, n, n, m);
}

StateSpace continuous_section(const ContinuousSection& s) {
  if (!(s.a0 > 0) || !std::isfinite(s.a0)) {
    throw std::invalid_argument("section '" + s.name + "': a0 must be positive (omega_n = sqrt(a0))");
  }
  const double wn = std::sqrt(s.a0);
  StateSpace ss;
  ss.a = DenseMatrix{2, 2, {0.0, wn, -wn, -s.a1}};
  ss.b = DenseMatrix{2, 1, {0.0, s.numerator / wn}};
  ss.c = DenseMatrix{1, 2, {1.0, 0.0}};
  ss.d = DenseMatrix{1, 1, {0.0}};
  return ss;
}

StateSpace discrete_section(const DiscreteSection& s) {
  StateSpace ss;
  ss.a = DenseMatrix{2, 2, {-s.a1, -s.a2, 1.0, 0.0}};
  ss.b = DenseMatrix{2, 1, {1.0, 0.0}};
  ss.c = DenseMatrix{1, 2, {s.b1 - s.b0 * s.a1, s.b2 - s.b0 * s.a2}};
  ss.d = DenseMatrix{1, 1, {s.b0}};
  return ss;
}

}  // namespace

DiscreteSection notch_section(const std::string& name, double frequency_hz, double alpha, double beta,
                              double period_s) {
  const double theta = 2.0 * kPi * frequency_hz * period_s;
  DiscreteSection s;
  s.name = name;
  s.b0 = 1.0;
  s.b1 = -2.0 * alpha * std::cos(theta);
  s.b2 = alpha * alpha;
  s.a1 = -2.0 * beta * std::cos(theta);
  s.a2 = beta * beta;
  return s;
}

namespace {
/// −0 → +0 (products with structural zeros), so reports show plain zeros.
void positive_zeros(std::initializer_list<DenseMatrix*> ms) {
  for (DenseMatrix* m : ms)
    for (double& v : m->values) v = v + 0.0;
}
}  // namespace

SectionsRealization realize_sections(const SectionsDescription& spec, double period_s) {
  if (spec.continuous.empty() && spec.discrete.empty()) throw std::invalid_argument("sections: none given");
  SectionsRealization r;
  // Continuous chain, then its ZOH.
  StateSpace chain;
  chain.d = DenseMatrix{1, 1, {1.0}};
  for (const ContinuousSection& s : spec.continuous) {
    chain = series(chain, continuous_section(s));
    r.state_names.push_back(s.name + "_p");
    r.state_names.push_back(s.name + "_v");
  }
  StateSpace plant;  // discrete
  plant.d = DenseMatrix{1, 1, {1.0}};
  std::vector<std::string> names;
  for (const DiscreteSection& s : spec.discrete) {
    plant = series(plant, discrete_section(s));
    names.push_back(s.name + "_z1");
    names.push_back(s.name + "_z2");
  }
  if (!spec.continuous.empty()) {
    r.a_c = chain.a;
    r.b_c = chain.b;
    r.c_c = chain.c;
    StateSpace zoh_chain;
    zoh(chain.a, chain.b, period_s, zoh_chain.a, zoh_chain.b, "sections: ZOH of the continuous chain");
    zoh_chain.c = chain.c;
    zoh_chain.d = chain.d;  // 0: every section is strictly proper
    plant = series(plant, zoh_chain);
  }
  names.insert(names.end(), r.state_names.begin(), r.state_names.end());
  r.state_names = names;
  r.phi_p = plant.a;
  r.gamma_p = plant.b;
  r.c_p = plant.c;
  r.d_p = plant.d;
  if (max_abs(plant.d) != 0) {
    throw std::invalid_argument("sections: the plant has a direct feedthrough (no continuous section)");
  }

  const SectionsDisturbance& dist = spec.disturbance;
  positive_zeros({&r.phi_p, &r.gamma_p, &r.c_p});
  if (dist.reading == DisturbanceReading::kNone) {
    r.phi = r.phi_p;
    r.gamma = r.gamma_p;
    r.c = r.c_p;
    return r;
  }
  if (dist.reading == DisturbanceReading::kOscillator) {
    const double w = dist.frequency_rad_s;
    const DenseMatrix a{2, 2, {0.0, 1.0, -w * w, 0.0}};
    const DenseMatrix b{2, 1, {0.0, dist.input_gain * w}};
    zoh(a, b, period_s, r.a_d, r.b_d, "sections: ZOH of the disturbance oscillator");
    r.c_d = DenseMatrix{1, 2, {0.0, dist.output_gain}};
  } else {
    r.a_d = dist.a_d;
    r.b_d = dist.b_d;
    r.c_d = dist.c_d;
  }
  const std::size_t np = r.phi_p.rows;
  const std::size_t nd = r.a_d.rows;
  const std::size_t n = np + nd;
  r.phi = DenseMatrix::zeros(n, n);
  set_block(r.phi, 0, 0, r.phi_p);
  set_block(r.phi, 0, np, r.gamma_p * r.c_d);
  set_block(r.phi, np, np, r.a_d);
  r.gamma = DenseMatrix::zeros(n, 1);
  set_block(r.gamma, 0, 0, r.gamma_p);
  r.b_w = DenseMatrix::zeros(n, r.b_d.cols);
  set_block(r.b_w, np, 0, r.b_d);
  r.c = DenseMatrix::zeros(1, n);
  set_block(r.c, 0, 0, r.c_p);
  r.c_bar = DenseMatrix::zeros(1, n);
  set_block(r.c_bar, 0, np, r.c_d);
  for (std::size_t i = 0; i < nd; ++i) r.state_names.push_back("d_x" + std::to_string(i + 1));
  r.exogenous_states = nd;
  positive_zeros({&r.phi, &r.gamma, &r.b_w, &r.c, &r.c_bar});
  return r;
}

}  // namespace oneshot::design
