/// @file plant_sections.hpp
/// @brief Plants given as transfer-function sections, realized into a discrete state space.
///
/// The "sections" plant form (used for the HDD plant of numre-petc.md §1):
///  * continuous all-pole 2nd-order sections b₀/(s² + a₁s + a₀) in series, each realized
///    as [position y, velocity ẏ/ω_n] with ω_n = √a₀:
///        A = [[0, ω_n], [−ω_n, −a₁]],  B = [0, b₀/ω_n]ᵀ,  C = [1, 0]
///    (balanced entries; a companion form of the product has coefficients up to ω⁶ and is
///    ill-conditioned), then the whole continuous chain is ZOH-discretized at T;
///  * discrete biquads (b₀ + b₁z⁻¹ + b₂z⁻²)/(1 + a₁z⁻¹ + a₂z⁻²) in series at the input
///    (before the continuous chain), each realized as
///        A = [[−a₁, −a₂], [1, 0]],  B = [1, 0]ᵀ,  C = [b₁ − b₀a₁, b₂ − b₀a₂],  D = b₀;
///    a notch N(z) = (1 − 2α cos θ z⁻¹ + α² z⁻²)/(1 − 2β cos θ z⁻¹ + β² z⁻²), θ = 2πfT;
///  * an optional input disturbance model (x_d⁺ = A_d x_d + B_d w, d = C_d x_d) appended
///    as exogenous states (eqs 3–4 of the brief):
///        Φ = [[Φ_p, Γ_p C_d], [0, A_d]],  Γ = [Γ_p; 0],  B_w = [0; B_d],
///        C = [C_p, 0],  C̄ = [0, C_d].
///    "oscillator" reading: ẍ₁ = −ω²x₁ + g ω w, x₂ = ẋ₁, ZOH at T, d = c·x₂;
///    "literal" reading: A_d, B_d, C_d taken as printed.
/// State order: biquad states (listed order), continuous section states (listed order),
/// disturbance states. The signal flows u (+ d) → biquads → continuous sections → y.
#pragma once

#include <string>
#include <vector>

#include "oneshot/design/dense_matrix.hpp"

namespace oneshot::design {

/// Continuous all-pole section b₀/(s² + a₁s + a₀).
struct ContinuousSection {
  std::string name;      ///< Names its states (<name>_p, <name>_v).
  double numerator = 0;  ///< b₀.
  double a1 = 0;         ///< a₁ (= 2ζω_n).
  double a0 = 0;         ///< a₀ (= ω_n², > 0).
};

/// Discrete biquad (b₀ + b₁z⁻¹ + b₂z⁻²)/(1 + a₁z⁻¹ + a₂z⁻²).
struct DiscreteSection {
  std::string name;              ///< Names its states (<name>_z1, <name>_z2).
  double b0 = 1, b1 = 0, b2 = 0; ///< Numerator.
  double a1 = 0, a2 = 0;         ///< Denominator (monic).
};

/// How the disturbance model is read.
enum class DisturbanceReading {
  kNone,        ///< No disturbance model.
  kOscillator,  ///< ẍ₁ = −ω²x₁ + g ω w, x₂ = ẋ₁, ZOH at T, d = c x₂.
  kLiteral,     ///< A_d, B_d, C_d as given.
};

/// The disturbance model of a sections plant.
struct SectionsDisturbance {
  DisturbanceReading reading = DisturbanceReading::kNone;  ///< Reading.
  double frequency_rad_s = 0;  ///< ω (oscillator).
  double input_gain = 0;       ///< g (oscillator).
  double output_gain = 0;      ///< c (oscillator).
  DenseMatrix a_d, b_d, c_d;   ///< Literal matrices (2×2, 2×1, 1×2 for one input).
};

/// A sections plant specification.
struct SectionsDescription {
  std::vector<ContinuousSection> continuous;  ///< In series, input first.
  std::vector<DiscreteSection> discrete;      ///< In series at the input, input first.
  SectionsDisturbance disturbance;            ///< Optional input disturbance model.
};

/// The realized model.
struct SectionsRealization {
  DenseMatrix a_c, b_c, c_c;       ///< Continuous chain before the ZOH.
  DenseMatrix phi_p, gamma_p, c_p; ///< Plant (biquads + ZOH chain), discrete, no disturbance.
  DenseMatrix d_p;                 ///< Plant feedthrough (1×1; 0 after the ZOH).
  DenseMatrix a_d, b_d, c_d;       ///< Disturbance model, discrete (empty without one).
  DenseMatrix phi, gamma, b_w, c, c_bar;  ///< Augmented model (= plant when no disturbance).
  std::vector<std::string> state_names;   ///< One per state of the augmented model.
  std::size_t exogenous_states = 0;       ///< Disturbance states (trailing).
};

/// Realizes `spec` at the period T (s); std::invalid_argument on a malformed spec (a₀ ≤ 0, …).
SectionsRealization realize_sections(const SectionsDescription& spec, double period_s);

/// Notch biquad of the brief: f (Hz), α, β at period T (s).
DiscreteSection notch_section(const std::string& name, double frequency_hz, double alpha, double beta,
                              double period_s);

}  // namespace oneshot::design
