/// @file ncs_reference.hpp
/// @brief The set-point of a study `ncs` run on the control grid: the brief's square wave ±A_r
///        (a node::SquareWaveReference: the firmware's own law) or steps from a study file's
///        `reference` (steps inline or from a CSV file), as the reference pair
///        (x_ref, u_ref) = (N_x r_k, N_u r_k) the controllers and the cost take.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <utility>
#include <vector>

#include "ncs_model.hpp"
#include "oneshot/matrix.hpp"
#include "oneshot/node/message.hpp"
#include "oneshot/node/square_wave_reference.hpp"

namespace oneshot::ncs {

/// A set-point r_k per period index k: a square wave (every H periods it flips sign) or steps
/// (r_k the value of the last change at or before k, r_0 before the first), for a plant of N
/// states and M inputs.
template <std::size_t N, std::size_t M>
class BasicSetpointReference {
 public:
  /// The changes of a stepped set-point: (period index k > 0, new value), k strictly increasing.
  using Changes = std::vector<std::pair<std::uint64_t, double>>;

  /// The square wave ±`amplitude`, `half_wave_periods` (≥ 1) periods per half wave.
  BasicSetpointReference(double amplitude, std::uint32_t half_wave_periods, const Vector<double, N>& nx,
                         const Vector<double, M>& nu)
      : amplitude_(amplitude), half_(half_wave_periods == 0 ? 1 : half_wave_periods),
        wave_(amplitude, half_wave_periods, nx, nu), nx_(nx), nu_(nu) {}

  /// Steps: r_0 = `r0`, then each change (k, value) from period k on.
  BasicSetpointReference(double r0, std::shared_ptr<const Changes> changes, const Vector<double, N>& nx,
                         const Vector<double, M>& nu)
      : amplitude_(r0), half_(0), wave_(r0, 1, nx, nu), changes_(std::move(changes)), nx_(nx), nu_(nu) {}

  /// r_k.
  double setpoint(node::SequenceNumber k) const {
    if (half_ != 0) return wave_.setpoint(k);
    const Changes& c = *changes_;
    const auto it = std::upper_bound(c.begin(), c.end(), std::uint64_t{k},
                                     [](std::uint64_t kk, const std::pair<std::uint64_t, double>& e) { return kk < e.first; });
    return it == c.begin() ? amplitude_ : std::prev(it)->second;
  }
  /// x_ref,k = N_x r_k.
  Vector<double, N> state(node::SequenceNumber k) const { return half_ != 0 ? wave_.state(k) : nx_ * setpoint(k); }
  /// u_ref,k = N_u r_k.
  Vector<double, M> input(node::SequenceNumber k) const { return half_ != 0 ? wave_.input(k) : nu_ * setpoint(k); }

  /// The periods k, 0 < k < `k_end`, at whose instant kh the set-point is switched (the square
  /// wave: every half wave, whatever its amplitude; steps: where the value changes).
  std::vector<std::uint64_t> switches(std::uint64_t k_end) const {
    std::vector<std::uint64_t> out;
    if (half_ != 0) {
      for (std::uint64_t k = half_; k < k_end; k += half_) out.push_back(k);
      return out;
    }
    for (const auto& [k, v] : *changes_)
      if (k < k_end) out.push_back(k);
    return out;
  }

 private:
  double amplitude_;  // A_r, or r_0 of steps
  std::uint32_t half_;  // periods per half wave (the switch instants); 0: steps
  node::SquareWaveReference<double, N, M> wave_;  // the square wave's law (unused for steps)
  std::shared_ptr<const Changes> changes_;
  Vector<double, N> nx_;
  Vector<double, M> nu_;
};

/// The set-point of the board's plant (2 states, 1 input).
using SetpointReference = BasicSetpointReference<kN, kM>;

}  // namespace oneshot::ncs
