/// @file petc_design.cpp
/// @brief Host design step of the petc study: plant facts, MRCI, DOB substitute, ESO.
#include "petc_design.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "oneshot/design/dense_ops.hpp"
#include "oneshot/design/plant_sections.hpp"
#include "oneshot/design/spectrum.hpp"

namespace oneshot::sim::petc {

using design::block;
using design::identity;
using design::max_abs;

namespace {

constexpr double kPi = 3.14159265358979323846;

/// Scalar C·v of a 1×n row and an n×1 column.
double dot_row(const DenseMatrix& row, const DenseMatrix& col) { return (row * col)(0, 0); }

/// Quadratic factors 1 + c1 z⁻¹ + c2 z⁻² of Π (1 − r z⁻¹) over `roots` (conjugates paired).
std::vector<std::pair<double, double>> quadratic_factors(std::vector<Complex> roots) {
  std::vector<std::pair<double, double>> out;
  std::vector<double> reals;
  std::vector<bool> used(roots.size(), false);
  for (std::size_t i = 0; i < roots.size(); ++i) {
    if (used[i]) continue;
    const Complex r = roots[i];
    if (std::abs(r.imag()) <= 1e-9 * std::max(1.0, std::abs(r))) {
      reals.push_back(r.real());
      used[i] = true;
      continue;
    }
    std::size_t best = roots.size();
    double dist = 0;
    for (std::size_t j = i + 1; j < roots.size(); ++j) {
      if (used[j]) continue;
      const double d = std::abs(roots[j] - std::conj(r));
      if (best == roots.size() || d < dist) {
        best = j;
        dist = d;
      }
    }
    if (best == roots.size() || dist > 1e-6 * std::max(1.0, std::abs(r)))
      throw std::invalid_argument("petc design: complex root without its conjugate");
    used[i] = used[best] = true;
    out.emplace_back(-2.0 * r.real(), std::norm(r));
  }
  std::sort(reals.begin(), reals.end());
  for (std::size_t i = 0; i < reals.size(); i += 2) {
    if (i + 1 < reals.size())
      out.emplace_back(-(reals[i] + reals[i + 1]), reals[i] * reals[i + 1]);
    else
      out.emplace_back(-reals[i], 0.0);
  }
  return out;
}

}  // namespace

std::string default_plant_path() { return ONESHOT_STUDY_PLANT_FILE; }

PlantFacts load_plant_facts(const std::string& path) {
  PlantFacts f;
  f.file = design::load_plant_file(path);
  const design::PlantDescription& p = f.file;
  if (p.form != design::PlantForm::kSections || !p.has_sections)
    throw std::invalid_argument(path + ": the petc study needs a plant in the 'sections' form");
  if (p.m() != 1 || p.p() != 1 || p.q() != 1 || p.exogenous_states != 2)
    throw std::invalid_argument(path + ": the petc study needs m = p = q = 1 and a 2-state disturbance model");
  if (p.disturbance_covariance_per_period.rows != 1 || p.measurement_covariance.rows != 1)
    throw std::invalid_argument(path + ": the petc study needs noise.disturbance_covariance_per_period and "
                                       "noise.measurement_covariance");
  f.period_s = p.period_us * 1e-6;
  const design::SectionsRealization r = design::realize_sections(p.sections, f.period_s);
  f.phi_p = r.phi_p;
  f.gamma_p = r.gamma_p;
  f.c_p = r.c_p;
  f.augmented = {"augmented", p.phi, p.gamma, p.b_w, p.c, p.c_bar,
                 p.disturbance_covariance_per_period(0, 0), p.measurement_covariance(0, 0)};
  const std::size_t n = f.phi_p.rows;
  f.poles = design::eigenvalues(f.phi_p);
  f.zeros = design::transmission_zeros(f.phi_p, f.gamma_p, f.c_p, DenseMatrix{1, 1, {0.0}});
  std::sort(f.zeros.begin(), f.zeros.end(), [](Complex a, Complex b) { return std::abs(a) > std::abs(b); });
  const design::SolveResult s = design::solve(identity(n) - f.phi_p, f.gamma_p);
  if (!s.ok) throw std::invalid_argument(path + ": the plant has a pole at z = 1 (no DC gain)");
  f.dc_gain = dot_row(f.c_p, s.x);
  DenseMatrix v = f.gamma_p;
  for (std::size_t k = 1; k <= n; ++k) {
    const double markov = dot_row(f.c_p, v);
    if (std::abs(markov) > 1e-12 * max_abs(f.c_p) * max_abs(v)) {
      f.relative_degree = k;
      f.leading_gain = markov;
      break;
    }
    v = f.phi_p * v;
  }
  if (f.relative_degree == 0) throw std::invalid_argument(path + ": the plant's output does not depend on u");
  return f;
}

MrciDesign design_mrci(double gain, const std::vector<double>& zeros, const std::vector<double>& poles,
                       std::size_t ratio) {
  if (ratio == 0) throw std::invalid_argument("MRCI: the ratio m must be at least 1");
  if (zeros.size() > poles.size()) throw std::invalid_argument("MRCI: C_D must be proper (no more zeros than poles)");
  for (std::size_t i = 0; i < poles.size(); ++i)
    for (std::size_t j = i + 1; j < poles.size(); ++j)
      if (poles[i] == poles[j]) throw std::invalid_argument("MRCI: repeated poles need higher-order blocks");
  MrciDesign d;
  d.gain = gain;
  d.zeros = zeros;
  d.poles = poles;
  d.ratio = ratio;
  d.threshold = std::exp(-1.0 / (2.5 * static_cast<double>(ratio)));
  d.feedthrough = zeros.size() == poles.size() ? gain : 0.0;
  // r_i = g Π_j (p_i − z_j) / Π_{l≠i} (p_i − p_l) (the D term removed when deg num = deg den:
  // the residue of C_D − D at p_i equals that of C_D).
  for (std::size_t i = 0; i < poles.size(); ++i) {
    double num = gain;
    for (double z : zeros) num *= poles[i] - z;
    double den = 1;
    for (std::size_t l = 0; l < poles.size(); ++l)
      if (l != i) den *= poles[i] - poles[l];
    MrciMode m;
    m.pole = poles[i];
    m.residue = num / den;
    m.slow = poles[i] >= d.threshold;
    if (m.slow) {
      double pm = 1, sum = 0;
      for (std::size_t j = 0; j < ratio; ++j) {
        sum += pm;
        pm *= poles[i];
      }
      m.slow_numerator = m.residue * sum;
      m.slow_pole = pm;
      m.phase = d.slow_count % ratio;
      ++d.slow_count;
    } else {
      ++d.fast_count;
    }
    d.modes.push_back(m);
  }
  // Fast part as one fraction: num = D Π(z − p) + Σ_f r_f Π_{l≠f}(z − p_l), den = Π(z − p).
  auto times_root = [](const std::vector<double>& poly, double root) {  // poly · (z − root)
    std::vector<double> out(poly.size() + 1, 0.0);
    for (std::size_t i = 0; i < poly.size(); ++i) {
      out[i] += poly[i];
      out[i + 1] -= root * poly[i];
    }
    return out;
  };
  d.fast_denominator = {1.0};
  for (const MrciMode& m : d.modes)
    if (!m.slow) d.fast_denominator = times_root(d.fast_denominator, m.pole);
  d.fast_numerator = d.fast_denominator;
  for (double& c : d.fast_numerator) c *= d.feedthrough;
  for (std::size_t f = 0; f < d.modes.size(); ++f) {
    if (d.modes[f].slow) continue;
    std::vector<double> term = {d.modes[f].residue};
    for (std::size_t l = 0; l < d.modes.size(); ++l)
      if (l != f && !d.modes[l].slow) term = times_root(term, d.modes[l].pole);
    const std::size_t off = d.fast_numerator.size() - term.size();
    for (std::size_t i = 0; i < term.size(); ++i) d.fast_numerator[off + i] += term[i];
  }
  const std::size_t s = d.slow_count;
  const std::size_t groups = (s + ratio - 1) / ratio;
  d.cs = s + d.fast_count == 0 ? 0.0 : static_cast<double>(s - groups) / static_cast<double>(s + d.fast_count);
  return d;
}

MrciDesign brief_mrci(std::size_t ratio) {
  // numre-petc.md §2: C_D(z) = 1.0882 (z − 0.9813)(z − 0.9681)(z + 1) / ((z − 1)(z − 0.8496)(z − 0.6137)).
  return design_mrci(1.0882, {0.9813, 0.9681, -1.0}, {1.0, 0.8496, 0.6137}, ratio);
}

Complex biquad_response(const Biquad& q, double theta) {
  const Complex zi = std::polar(1.0, -theta);
  return (q.b0 + q.b1 * zi + q.b2 * zi * zi) / (1.0 + q.a1 * zi + q.a2 * zi * zi);
}

DobDesign design_dob(const PlantFacts& plant, double cutoff_hz) {
  const double t = plant.period_s;
  if (!(cutoff_hz > 0) || !(cutoff_hz < 0.5 / t)) throw std::invalid_argument("DOB: the Q cutoff must lie in (0, Nyquist)");
  const std::size_t n = plant.poles.size();
  if (plant.zeros.size() + plant.relative_degree != n)
    throw std::invalid_argument("DOB: zeros and relative degree of the plant do not add up to its order");
  DobDesign d;
  d.cutoff_hz = cutoff_hz;
  const double k = std::tan(kPi * cutoff_hz * t);
  const double norm = 1.0 / (1.0 + std::sqrt(2.0) * k + k * k);
  d.q.b0 = k * k * norm;
  d.q.b1 = 2.0 * d.q.b0;
  d.q.b2 = d.q.b0;
  d.q.a1 = 2.0 * (k * k - 1.0) * norm;
  d.q.a2 = (1.0 - std::sqrt(2.0) * k + k * k) * norm;
  // G_s: zeros outside the unit circle replaced by their DC gains (1 − z_u).
  Complex gs = plant.leading_gain;
  std::vector<Complex> kept;
  for (const Complex z : plant.zeros) {
    if (std::abs(z) >= 1.0) {
      d.replaced_zeros.push_back(z);
      gs *= 1.0 - z;
    } else {
      kept.push_back(z);
    }
  }
  d.delay = n - kept.size();
  d.inverse_gain = 1.0 / gs.real();
  // z^{−ρ} G_s⁻¹ = (1/g_s) Π (1 − p z⁻¹) / Π_kept (1 − z z⁻¹) (ρ zeros at the origin).
  const auto num = quadratic_factors(plant.poles);
  const auto den = quadratic_factors(kept);
  for (std::size_t i = 0; i < std::max(num.size(), den.size()); ++i) {
    Biquad b;
    if (i < num.size()) {
      b.b1 = num[i].first;
      b.b2 = num[i].second;
    }
    if (i < den.size()) {
      b.a1 = den[i].first;
      b.a2 = den[i].second;
    }
    d.inverse.push_back(b);
  }
  // γ on a log grid 1 Hz … Nyquist: d → d − d̂ is 1 − D₂G, u → d − d̂ is −(D₁ + D₂G).
  d.grid_points = 400;
  const double f_hi = 0.5 / t;
  for (std::size_t i = 0; i < d.grid_points; ++i) {
    const double f = std::pow(10.0, std::log10(f_hi) * static_cast<double>(i) / static_cast<double>(d.grid_points - 1));
    const double theta = 2.0 * kPi * f * t;
    const Complex z = std::polar(1.0, theta);
    Complex g = plant.leading_gain;
    for (const Complex zz : plant.zeros) g *= z - zz;
    for (const Complex p : plant.poles) g /= z - p;
    const Complex q = biquad_response(d.q, theta);
    Complex inv = d.inverse_gain;
    for (const Biquad& b : d.inverse) inv *= biquad_response(b, theta);
    const Complex d2 = q * inv;
    const Complex d1 = -q * std::pow(z, -static_cast<double>(d.delay));
    d.gamma_d = std::max(d.gamma_d, std::abs(1.0 - d2 * g));
    d.gamma_u = std::max(d.gamma_u, std::abs(d1 + d2 * g));
  }
  return d;
}

EstimatorModel plant_only_model(const PlantFacts& plant, double w_d) {
  const std::size_t n = plant.phi_p.rows;
  return {"plant-only", plant.phi_p, plant.gamma_p, plant.gamma_p, plant.c_p, DenseMatrix::zeros(1, n), w_d,
          plant.augmented.v};
}

EstimatorModel eso_model(const PlantFacts& plant, double q_d) {
  const std::size_t n = plant.phi_p.rows;
  EstimatorModel m{"eso", DenseMatrix::zeros(n + 1, n + 1), DenseMatrix::zeros(n + 1, 1), DenseMatrix::zeros(n + 1, 1),
                   DenseMatrix::zeros(1, n + 1), DenseMatrix::zeros(1, n + 1), q_d, plant.augmented.v};
  design::set_block(m.a, 0, 0, plant.phi_p);
  design::set_block(m.a, 0, n, plant.gamma_p);
  m.a(n, n) = 1.0;
  design::set_block(m.b, 0, 0, plant.gamma_p);
  m.b_w(n, 0) = 1.0;
  design::set_block(m.c, 0, 0, plant.c_p);
  m.c_bar(0, n) = 1.0;
  return m;
}

std::vector<double> disturbance_variance(const PlantFacts& plant, std::size_t steps) {
  const std::size_t n = plant.augmented.a.rows;
  const std::size_t e = plant.file.exogenous_states;
  const DenseMatrix ad = block(plant.augmented.a, n - e, n - e, e, e);
  const DenseMatrix bd = block(plant.augmented.b_w, n - e, 0, e, 1);
  const DenseMatrix cd = block(plant.augmented.c_bar, 0, n - e, 1, e);
  const DenseMatrix q = bd * design::transpose(bd) * plant.augmented.w;
  DenseMatrix p = DenseMatrix::zeros(e, e);
  std::vector<double> out;
  for (std::size_t k = 0; k <= steps; ++k) {
    out.push_back((cd * p * design::transpose(cd))(0, 0));
    p = ad * p * design::transpose(ad) + q;
  }
  return out;
}

nlohmann::json complex_json(const std::vector<Complex>& v) {
  nlohmann::json j = nlohmann::json::array();
  for (const Complex c : v) j.push_back({c.real(), c.imag()});
  return j;
}

nlohmann::json design_json(const PlantFacts& plant, const MrciDesign& mrci, const DobDesign& dob,
                           const std::vector<double>& var_d) {
  nlohmann::json j;
  j["plant"] = {{"file", plant.file.source},
                {"period_us", plant.file.period_us},
                {"states_plant", plant.phi_p.rows},
                {"states_augmented", plant.augmented.a.rows},
                {"dc_gain", plant.dc_gain},
                {"zeros", complex_json(plant.zeros)},
                {"poles", complex_json(plant.poles)},
                {"relative_degree", plant.relative_degree},
                {"leading_gain", plant.leading_gain}};
  // Printed values of the paper (brief §2) for the comparison.
  const double printed_slow[2] = {0.04484, -1.6365};
  nlohmann::json slow = nlohmann::json::array();
  nlohmann::json fast = nlohmann::json::array();
  std::size_t si = 0;
  for (const MrciMode& m : mrci.modes) {
    if (m.slow) {
      nlohmann::json s = {{"pole", m.pole}, {"residue", m.residue}, {"numerator", m.slow_numerator},
                          {"slow_pole", m.slow_pole}, {"phase", m.phase}};
      if (mrci.ratio == 2 && si < 2) {
        s["printed_numerator"] = printed_slow[si];
        s["relative_difference"] = std::abs(m.slow_numerator - printed_slow[si]) / std::abs(printed_slow[si]);
      }
      ++si;
      slow.push_back(s);
    } else {
      fast.push_back({{"pole", m.pole}, {"residue", m.residue}});
    }
  }
  j["mrci"] = {{"gain", mrci.gain},
               {"zeros", mrci.zeros},
               {"poles", mrci.poles},
               {"ratio", mrci.ratio},
               {"slow_threshold", mrci.threshold},
               {"feedthrough", mrci.feedthrough},
               {"slow_modes", slow},
               {"fast_modes", fast},
               {"fast_part", {{"numerator", mrci.fast_numerator}, {"denominator", mrci.fast_denominator},
                              {"printed", "(1.0882 z + 1.84)/(z - 0.6137) at m = 2"}}},
               {"slow_count", mrci.slow_count},
               {"fast_count", mrci.fast_count},
               {"cs", mrci.cs}};
  nlohmann::json inv = nlohmann::json::array();
  for (const Biquad& b : dob.inverse) inv.push_back({b.b0, b.b1, b.b2, 1.0, b.a1, b.a2});
  j["dob"] = {{"cutoff_hz", dob.cutoff_hz},
              {"q", {dob.q.b0, dob.q.b1, dob.q.b2, 1.0, dob.q.a1, dob.q.a2}},
              {"replaced_zeros", complex_json(dob.replaced_zeros)},
              {"delay", dob.delay},
              {"inverse_gain", dob.inverse_gain},
              {"inverse_sections", inv},
              {"gamma_d_to_error", dob.gamma_d},
              {"gamma_u_to_error", dob.gamma_u},
              {"grid_points", dob.grid_points},
              {"note", "gamma is the peak on the grid of the estimation-error maps d -> d - dhat and u -> d - dhat; "
                       "eq. 18's generalized plant M and its weights are not given, so F_l(M, D) itself is not formed"}};
  double mean = 0;
  for (double x : var_d) mean += x;
  mean /= static_cast<double>(var_d.size());
  j["disturbance"] = {{"variance_at_end", var_d.back()}, {"variance_mean", mean}, {"steps", var_d.size() - 1}};
  return j;
}

}  // namespace oneshot::sim::petc
