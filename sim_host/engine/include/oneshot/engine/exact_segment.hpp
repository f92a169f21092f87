/// @file exact_segment.hpp
/// @brief The engine's one exact propagation step for a linear plant with held inputs:
///        state map, input map and cost Gramian of an interval from one Van Loan exponential,
///        cached per interval length, and the noise bridge of a state trace.
///
/// For ẋ = A x + B v with v (U columns) held over [0, Δ] and z = [e; v]:
///     e(Δ) = Φ(Δ) e + Γ(Δ) v,   ∫₀^Δ eᵀ Q1c e ds = zᵀ G(Δ) z,
/// from exp([[−Fᵀ, blkdiag(Q1c, 0)], [0, F]] Δ) = [[·, E12], [0, E22]] with F = [[A, B], [0, 0]]:
/// E22 = [[Φ, Γ], [0, I]] and G = E22ᵀ E12 (Van Loan, 1978).
#pragma once

#include <cstddef>
#include <cstdint>
#include <unordered_map>
#include <vector>

#include "oneshot/assert_handler.hpp"
#include "oneshot/engine/process_noise.hpp"
#include "oneshot/engine/quadratic_form.hpp"
#include "oneshot/engine/random_stream.hpp"
#include "oneshot/engine/sim_time.hpp"
#include "oneshot/matrix.hpp"
#include "oneshot/matrix_exponential.hpp"

namespace oneshot::engine {

/// The exact map of one interval: Φ(Δ), Γ(Δ) (all U held input columns) and G(Δ).
template <std::size_t N, std::size_t U>
struct ExactSegment {
  Matrix<double, N, N> phi;          ///< Φ(Δ).
  Matrix<double, N, U> gamma;        ///< Γ(Δ) = ∫₀^Δ e^{As} ds B.
  Matrix<double, N + U, N + U> g;    ///< ∫₀^Δ eᵀQ1c e ds = zᵀ G z, z = [e; v].
};

/// Exact interval maps of ẋ = A x + B v, cached by interval length in ns (the cache is
/// cleared when it passes `capacity` entries, so irregular timing cannot grow it without bound).
template <std::size_t N, std::size_t U>
class ExactSegmentCache {
 public:
  static constexpr std::size_t kK = N + U;  ///< Size of z = [e; v].
  using Segment = ExactSegment<N, U>;

  /// A (1/s), B (all held input columns) and the state cost weight Q1c; at most about
  /// `capacity` interval lengths kept.
  ExactSegmentCache(const Matrix<double, N, N>& a, const Matrix<double, N, U>& b, const Matrix<double, N, N>& q1c,
                    std::size_t capacity = 8192)
      : capacity_(capacity) {
    f_.template set_block<0, 0>(a);
    f_.template set_block<0, N>(b);
    w_.template set_block<0, 0>(q1c);
  }

  /// The map of an interval of `delta_ns` ns (> 0).
  const Segment& get(std::int64_t delta_ns) {
    const auto it = segments_.find(delta_ns);
    if (it != segments_.end()) return it->second;
    if (segments_.size() > capacity_) segments_.clear();
    const double d = static_cast<double>(delta_ns) * 1e-9;
    Matrix<double, 2 * kK, 2 * kK> v;
    v.template set_block<0, 0>(-(f_.transposed() * d));
    v.template set_block<0, kK>(w_ * d);
    v.template set_block<kK, kK>(f_ * d);
    Matrix<double, 2 * kK, 2 * kK> e;
    ONESHOT_ASSERT(matrix_exponential(v, e) == Status::kOk);
    const Matrix<double, kK, kK> e22 = e.template block<kK, kK, kK, kK>();
    Segment s;
    s.phi = e22.template block<0, 0, N, N>();
    s.gamma = e22.template block<0, N, N, U>();
    s.g = e22.transposed() * e.template block<0, kK, kK, kK>();
    mirror_upper(s.g);
    return segments_.emplace(delta_ns, s).first->second;
  }

 private:
  Matrix<double, kK, kK> f_;
  Matrix<double, kK, kK> w_;
  std::size_t capacity_;
  std::unordered_map<std::int64_t, Segment> segments_;
};

/// Adds the process-noise path to trace points recorded noise-free inside one interval:
/// points [first, end) lie in (start, t_end], `n_end` is the noise drawn for the whole
/// interval; each point gets a bridge draw from `rng` conditioned on the previous point and
/// on n_end: the noise still to come after t_prev is n_end − Φ(t_end − t_prev) n(t_prev).
/// `active`: the noisy states' count (ProcessNoise::bridge()).
template <std::size_t N, typename Sample>
void bridge_trace_noise(std::vector<Sample>& trace, std::size_t first, SimTime start, SimTime t_end,
                        const Vector<double, N>& n_end, const ProcessNoise<N>& noise, RandomStream& rng,
                        std::size_t active = N) {
  Vector<double, N> n_prev{};
  SimTime t_prev = start;
  for (std::size_t i = first; i < trace.size(); ++i) {
    const SimTime s = trace[i].t;
    const Vector<double, N> rest = n_end - noise.transition(t_end - t_prev) * n_prev;
    const Vector<double, N> n_s = noise.transition(s - t_prev) * n_prev + noise.bridge(s - t_prev, t_end - t_prev, rest, rng, active);
    trace[i].x = trace[i].x + n_s;
    n_prev = n_s;
    t_prev = s;
  }
}

}  // namespace oneshot::engine
