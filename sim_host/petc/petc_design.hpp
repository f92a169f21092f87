/// @file petc_design.hpp
/// @brief Host design step of the petc study (numre-petc.md §1, §2, §6): the plant's
///        structure, the MRCI decomposition of C_D, the DOB substitute and the ESO model.
#pragma once

#include <complex>
#include <cstddef>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "oneshot/design/dense_matrix.hpp"
#include "oneshot/design/plant_description.hpp"

namespace oneshot::sim::petc {

using design::DenseMatrix;
using Complex = std::complex<double>;

/// A discrete model for a NUMRE: x⁺ = A x + B u + B_w w, y = C x, d̂ = C̄ x.
struct EstimatorModel {
  std::string name;           ///< "augmented", "plant-only", "eso".
  DenseMatrix a, b, b_w, c, c_bar;  ///< Matrices (n×n, n×1, n×1, 1×n, 1×n).
  double w = 0;               ///< W: variance of w per period.
  double v = 0;               ///< V: variance of v.
};

/// The plant of §1 and what the design reports about it.
struct PlantFacts {
  design::PlantDescription file;    ///< The plant file as read.
  double period_s = 0;              ///< T.
  DenseMatrix phi_p, gamma_p, c_p;  ///< Plant without the disturbance model (10 states).
  EstimatorModel augmented;         ///< 12-state model (true plant, case 3–5 NUMRE).
  std::vector<Complex> poles;       ///< Eigenvalues of Φ_p.
  std::vector<Complex> zeros;       ///< Finite transmission zeros of (Φ_p, Γ_p, C_p).
  double dc_gain = 0;               ///< C_p (I − Φ_p)⁻¹ Γ_p.
  std::size_t relative_degree = 0;  ///< First k with C_p Φ_p^{k−1} Γ_p ≠ 0.
  double leading_gain = 0;          ///< C_p Φ_p^{ρ−1} Γ_p: G = g Π(z − z_i)/Π(z − p_i).
};

/// Reads the plant file (hdd_numre.json: sections form with a disturbance model) and
/// analyses it; PlantError / std::invalid_argument naming what is wrong.
PlantFacts load_plant_facts(const std::string& path);

/// The built-in plant file path (lut_gen/plants/hdd_numre.json of the source tree).
std::string default_plant_path();

/// One mode r/(z − p) of the partial fractions, and its slow form at ratio m.
struct MrciMode {
  double pole = 0;            ///< p.
  double residue = 0;         ///< r.
  bool slow = false;          ///< p ≥ e^{−1/(2.5 m)}.
  double slow_numerator = 0;  ///< r Σ_{j<m} p^j (slow modes).
  double slow_pole = 0;       ///< p^m (slow modes).
  std::size_t phase = 0;      ///< Update phase (slow modes: index mod m).
};

/// The MRCI decomposition of C_D = g Π(z − z_j)/Π(z − p_i) (proper, distinct real poles).
struct MrciDesign {
  double gain = 0;                 ///< g.
  std::vector<double> zeros, poles;  ///< Of C_D.
  std::size_t ratio = 2;           ///< m.
  double threshold = 0;            ///< e^{−1/(2.5 m)}.
  double feedthrough = 0;          ///< D (= g for deg num = deg den).
  std::vector<MrciMode> modes;     ///< One per pole, in the given order.
  std::size_t slow_count = 0;      ///< s.
  std::size_t fast_count = 0;      ///< n.
  double cs = 0;                   ///< (s − ⌈s/m⌉)/(s + n).
  std::vector<double> fast_numerator;    ///< Fast part D + Σ_fast r/(z − p): numerator, highest power first.
  std::vector<double> fast_denominator;  ///< Its denominator Π (z − p_fast), monic, highest power first.
};

/// Partial fractions, slow/fast split and slow modes; std::invalid_argument for a
/// non-proper C_D, repeated poles or m = 0.
MrciDesign design_mrci(double gain, const std::vector<double>& zeros, const std::vector<double>& poles, std::size_t ratio);

/// The brief's C_D at ratio m.
MrciDesign brief_mrci(std::size_t ratio);

/// (b0 + b1 z⁻¹ + b2 z⁻²)/(1 + a1 z⁻¹ + a2 z⁻²).
struct Biquad {
  double b0 = 1, b1 = 0, b2 = 0, a1 = 0, a2 = 0;  ///< Coefficients.
};

/// The DOB substitute of §6.
struct DobDesign {
  double cutoff_hz = 0;            ///< Q's cutoff.
  Biquad q;                        ///< 2nd-order Butterworth (bilinear, prewarped).
  std::vector<Complex> replaced_zeros;  ///< Zeros of G outside the unit circle (replaced by their DC gains).
  std::size_t delay = 0;           ///< ρ: relative degree of G_s.
  double inverse_gain = 0;         ///< 1/g_s.
  std::vector<Biquad> inverse;     ///< z^{−ρ} G_s⁻¹ = inverse_gain · Π sections.
  double gamma_d = 0;              ///< max_ω |1 − D₂ G| (d → d − d̂) on the grid.
  double gamma_u = 0;              ///< max_ω |D₁ + D₂ G| (u → d − d̂) on the grid.
  std::size_t grid_points = 0;     ///< Frequencies of the grid (log, 1 Hz … Nyquist).
};

/// Designs the DOB for the plant at Q cutoff `cutoff_hz`.
DobDesign design_dob(const PlantFacts& plant, double cutoff_hz);

/// Frequency response of a biquad at z = e^{jθ}.
Complex biquad_response(const Biquad& q, double theta);

/// Plant-only model (10 states, d as white input noise of variance `w_d`, B_w = Γ_p).
EstimatorModel plant_only_model(const PlantFacts& plant, double w_d);

/// ESO model (11 states: random-walk input disturbance with increment variance `q_d`).
EstimatorModel eso_model(const PlantFacts& plant, double q_d);

/// E[d_k²] of the disturbance model from x_d(0) = 0, for k = 0 … steps (Lyapunov recursion).
std::vector<double> disturbance_variance(const PlantFacts& plant, std::size_t steps);

/// JSON of a complex list: [[re, im], …].
nlohmann::json complex_json(const std::vector<Complex>& v);

/// The `design` experiment's JSON.
nlohmann::json design_json(const PlantFacts& plant, const MrciDesign& mrci, const DobDesign& dob,
                           const std::vector<double>& var_d);

}  // namespace oneshot::sim::petc
