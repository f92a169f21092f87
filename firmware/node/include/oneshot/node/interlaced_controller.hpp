/// @file interlaced_controller.hpp
/// @brief Multi-rate interlaced controller (MRCI, numre-petc.md §2): C_D split into
///        first-order modes, the slow ones run at ratio m on interlaced phases.
///
///     C_D(z) = D + Σ_f r_f/(z − p_f) + Σ_i r_i/(z − p_i)
/// Fast mode f (every period):  u_f,k = r_f x_f,  x_f ← p_f x_f + e_k.
/// Slow mode i at ratio m (eq. 19, first order: r (Σ_j p^{m−1−j})/(z^m − p^m)):
///     e is sampled at k = m j (or at the mode's own update, option);
///     at k ≡ φ_i (mod m), φ_i = i mod m:  out_i = r_i x_i (held m periods),
///                                          x_i ← p_i^m x_i + (Σ_{j=0}^{m−1} p_i^{m−1−j}) e_sample.
///     u_k = D e_k + Σ_f u_f,k + Σ_i out_i.
/// With m = 1 this is C_D itself. The mode state is a plain value, so a node can store it
/// with a packet and restart a cascade from it.
#pragma once

#include <cstddef>
#include <cstdint>

namespace oneshot::node {

/// One real first-order mode r/(z − p).
template <typename S>
struct FirstOrderMode {
  S residue = S(0);  ///< r.
  S pole = S(0);     ///< p.
};

/// Parameters of an interlaced controller with kFast fast and kSlow slow modes.
template <typename S, std::size_t kFast, std::size_t kSlow>
struct InterlacedConfig {
  S feedthrough = S(0);                 ///< D.
  FirstOrderMode<S> fast[kFast];        ///< Fast modes (every period).
  FirstOrderMode<S> slow[kSlow];        ///< Slow modes (ratio m).
  std::uint32_t ratio = 1;              ///< m ≥ 1.
  bool sample_at_update = false;        ///< Slow mode i samples e at its own update (option of §2).
};

/// The interlaced controller (single error input, single output).
template <typename S, std::size_t kFast, std::size_t kSlow>
class InterlacedController {
  static_assert(kFast > 0 && kSlow > 0, "interlaced controller needs a fast and a slow mode");

 public:
  /// Placeholder (all modes zero, m = 1): storage for a state assigned later.
  constexpr InterlacedController() = default;
  /// Controller at rest with `cfg`; m = 0 is taken as 1.
  constexpr explicit InterlacedController(const InterlacedConfig<S, kFast, kSlow>& cfg) : cfg_(cfg) {
    if (cfg_.ratio == 0) cfg_.ratio = 1;
    for (std::size_t i = 0; i < kSlow; ++i) {
      S pm = S(1);
      S sum = S(0);
      for (std::uint32_t j = 0; j < cfg_.ratio; ++j) {
        sum = sum + pm;  // Σ_{j=0}^{m−1} p^j = Σ p^{m−1−j}
        pm = pm * cfg_.slow[i].pole;
      }
      pole_m_[i] = pm;
      input_gain_[i] = sum;
    }
  }

  /// u_k for the error e_k at absolute period k (periods must come in order, one by one).
  constexpr S step(std::uint64_t k, S e) {
    // k mod m once, in 32 bits when k fits (no 64-bit division on a 32-bit core).
    const std::uint32_t phase = k <= 0xFFFFFFFFU ? static_cast<std::uint32_t>(k) % cfg_.ratio
                                                 : static_cast<std::uint32_t>(k % cfg_.ratio);
    if (phase == 0) e_sample_ = e;
    S u = cfg_.feedthrough * e;
    for (std::size_t f = 0; f < kFast; ++f) {
      u = u + cfg_.fast[f].residue * xf_[f];
      xf_[f] = cfg_.fast[f].pole * xf_[f] + e;
    }
    macs_ += 1 + 2 * kFast;
    for (std::size_t i = 0; i < kSlow; ++i) {
      if (phase == i % cfg_.ratio) {
        out_[i] = cfg_.slow[i].residue * xs_[i];
        xs_[i] = pole_m_[i] * xs_[i] + input_gain_[i] * (cfg_.sample_at_update ? e : e_sample_);
        macs_ += 3;
      }
      u = u + out_[i];
    }
    return u;
  }

  /// Everything step() changes (a node stores this per packet entry, not the constants).
  struct Modes {
    S xf[kFast]{};             ///< Fast mode states.
    S xs[kSlow]{};             ///< Slow mode states.
    S out[kSlow]{};            ///< Held slow outputs.
    S e_sample = S(0);         ///< Sampled error.
    std::uint64_t macs = 0;    ///< Multiply-add counter.
  };
  /// The mode states.
  constexpr Modes modes() const {
    Modes m;
    for (std::size_t f = 0; f < kFast; ++f) m.xf[f] = xf_[f];
    for (std::size_t i = 0; i < kSlow; ++i) {
      m.xs[i] = xs_[i];
      m.out[i] = out_[i];
    }
    m.e_sample = e_sample_;
    m.macs = macs_;
    return m;
  }
  /// Restores mode states saved by modes() (same configuration).
  constexpr void set_modes(const Modes& m) {
    for (std::size_t f = 0; f < kFast; ++f) xf_[f] = m.xf[f];
    for (std::size_t i = 0; i < kSlow; ++i) {
      xs_[i] = m.xs[i];
      out_[i] = m.out[i];
    }
    e_sample_ = m.e_sample;
    macs_ = m.macs;
  }

  /// Slow mode i's held output.
  constexpr S slow_output(std::size_t i) const { return out_[i]; }
  /// p_i^m.
  constexpr S slow_pole_power(std::size_t i) const { return pole_m_[i]; }
  /// Σ_j p_i^{m−1−j}: the slow numerator is r_i times this.
  constexpr S slow_input_gain(std::size_t i) const { return input_gain_[i]; }
  /// Multiply-adds executed so far.
  constexpr std::uint64_t macs() const { return macs_; }

 private:
  InterlacedConfig<S, kFast, kSlow> cfg_{};
  S pole_m_[kSlow]{};
  S input_gain_[kSlow]{};
  S xf_[kFast]{};
  S xs_[kSlow]{};
  S out_[kSlow]{};
  S e_sample_ = S(0);
  std::uint64_t macs_ = 0;
};

}  // namespace oneshot::node
