/// @file square_wave_reference.hpp
/// @brief Set-point of the networked loops: a square wave ±A_r of period T_r switching on
///        the control grid, as the reference pair (x_ref, u_ref) = (N_x r, N_u r).
///
/// r_k = +A_r while ⌊k / H⌋ is even, −A_r while it is odd, H = T_r / (2h) periods per half
/// wave, so the command that targets period k (t_k, or kh in the baseline) uses the
/// set-point valid at that instant, never one read late.
#pragma once

#include <cstddef>
#include <cstdint>

#include "oneshot/matrix.hpp"
#include "oneshot/node/message.hpp"

namespace oneshot::node {

/// Square-wave set-point on one tracked output (columns N_x, N_u of that output).
template <typename S, std::size_t N, std::size_t M>
class SquareWaveReference {
 public:
  /// Amplitude A_r, H periods per half wave (≥ 1), feed-forward columns for that output.
  constexpr SquareWaveReference(S amplitude, std::uint32_t half_wave_periods, const Vector<S, N>& nx,
                                const Vector<S, M>& nu)
      : amplitude_(amplitude), half_(half_wave_periods == 0 ? 1 : half_wave_periods), nx_(nx), nu_(nu) {}
  /// r_k.
  constexpr S setpoint(SequenceNumber k) const { return ((k / half_) % 2U) == 0U ? amplitude_ : -amplitude_; }
  /// x_ref,k = N_x r_k.
  constexpr Vector<S, N> state(SequenceNumber k) const { return nx_ * setpoint(k); }
  /// u_ref,k = N_u r_k.
  constexpr Vector<S, M> input(SequenceNumber k) const { return nu_ * setpoint(k); }

 private:
  S amplitude_;
  std::uint32_t half_;
  Vector<S, N> nx_;
  Vector<S, M> nu_;
};

/// Clamps u into [lo, hi] entry by entry; true when any entry was clamped.
template <typename S, std::size_t M>
constexpr bool saturate(Vector<S, M>& u, const Vector<S, M>& lo, const Vector<S, M>& hi) {
  bool clamped = false;
  for (std::size_t j = 0; j < M; ++j) {
    if (u[j] < lo[j]) {
      u[j] = lo[j];
      clamped = true;
    } else if (hi[j] < u[j]) {
      u[j] = hi[j];
      clamped = true;
    }
  }
  return clamped;
}

}  // namespace oneshot::node
