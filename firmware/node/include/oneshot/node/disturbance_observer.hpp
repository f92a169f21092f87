/// @file disturbance_observer.hpp
/// @brief Input-disturbance estimates for the PETC controller (numre-petc.md §6).
///
/// ModelDisturbance: d̂ = C̄ x̂ from a model that carries the disturbance states.
/// DisturbanceObserver: the host-designed substitute of the paper's H∞ observer,
///     d̂ = D₁ u + D₂ ŷ,   D₁ = −Q(z) z^{−ρ},   D₂ = Q(z) z^{−ρ} G_s⁻¹(z),
/// with z^{−ρ} G_s⁻¹ realized as g · Π (b₀ + b₁z⁻¹ + b₂z⁻²)/(1 + a₁z⁻¹ + a₂z⁻²) (biproper
/// sections, transposed direct form II) and Q a biquad. d̂_k uses ŷ up to k and u up to
/// k − 1 (ρ ≥ 1): estimate(ŷ_k) before u_k is known, commit(u_k) after.
#pragma once

#include <cstddef>
#include <cstdint>

namespace oneshot::node {

/// (b₀ + b₁z⁻¹ + b₂z⁻²)/(1 + a₁z⁻¹ + a₂z⁻²).
template <typename S>
struct BiquadCoefficients {
  S b0 = S(1), b1 = S(0), b2 = S(0);  ///< Numerator.
  S a1 = S(0), a2 = S(0);             ///< Denominator (monic).
};

/// One biquad section with its state (transposed direct form II).
template <typename S>
struct BiquadState {
  S s1 = S(0), s2 = S(0);  ///< Delay elements.
  /// y = b₀x + s₁;  s₁ = b₁x − a₁y + s₂;  s₂ = b₂x − a₂y.
  constexpr S step(const BiquadCoefficients<S>& c, S x) {
    const S y = c.b0 * x + s1;
    s1 = c.b1 * x - c.a1 * y + s2;
    s2 = c.b2 * x - c.a2 * y;
    return y;
  }
};

/// d̂ = C̄ x̂ (the model's own disturbance states; nothing to run).
template <typename S>
class ModelDisturbance {
 public:
  /// d̂_k: the model's estimate.
  constexpr S estimate(S /*y_hat*/, S model_d) { return model_d; }
  /// Nothing to remember.
  constexpr void commit(S /*u*/) {}
  /// No extra multiply-adds.
  constexpr std::uint64_t macs() const { return 0; }
};

/// Parameters of a DisturbanceObserver with kSections inverse sections and delays ≤ kMaxDelay.
template <typename S, std::size_t kSections, std::size_t kMaxDelay>
struct DisturbanceObserverConfig {
  BiquadCoefficients<S> q;                    ///< Q(z), unit DC gain.
  BiquadCoefficients<S> inverse[kSections];   ///< Sections of z^{−ρ} G_s⁻¹ / g.
  S inverse_gain = S(1);                      ///< g.
  std::uint32_t delay = 1;                    ///< ρ (1 … kMaxDelay).
};

/// The DOB substitute of §6.
template <typename S, std::size_t kSections, std::size_t kMaxDelay>
class DisturbanceObserver {
  static_assert(kMaxDelay > 0, "the observer needs a delay line");

 public:
  /// Placeholder (identity sections, ρ = 1): storage for a state assigned later.
  constexpr DisturbanceObserver() = default;
  /// Observer at rest.
  constexpr explicit DisturbanceObserver(const DisturbanceObserverConfig<S, kSections, kMaxDelay>& cfg) : cfg_(cfg) {
    if (cfg_.delay == 0) cfg_.delay = 1;
    if (cfg_.delay > kMaxDelay) cfg_.delay = kMaxDelay;  // the host design refuses this case first
  }
  /// d̂_k from ŷ_k (the model estimate is ignored).
  constexpr S estimate(S y_hat, S /*model_d*/) {
    const std::uint32_t rho = cfg_.delay;
    const S u_delayed = count_ >= rho ? ring_[(count_ - rho) % kMaxDelay] : S(0);
    const S d1 = q_u_.step(cfg_.q, u_delayed);
    S v = y_hat * cfg_.inverse_gain;
    for (std::size_t i = 0; i < kSections; ++i) v = inv_[i].step(cfg_.inverse[i], v);
    const S d2 = q_y_.step(cfg_.q, v);
    macs_ += 5 * (2 + kSections) + 1;
    return d2 - d1;
  }
  /// Remembers u_k.
  constexpr void commit(S u) {
    ring_[count_ % kMaxDelay] = u;
    ++count_;
  }
  /// Multiply-adds executed so far.
  constexpr std::uint64_t macs() const { return macs_; }

 private:
  DisturbanceObserverConfig<S, kSections, kMaxDelay> cfg_{};
  BiquadState<S> q_u_{};
  BiquadState<S> q_y_{};
  BiquadState<S> inv_[kSections]{};
  S ring_[kMaxDelay]{};
  std::uint32_t count_ = 0;
  std::uint64_t macs_ = 0;
};

}  // namespace oneshot::node
