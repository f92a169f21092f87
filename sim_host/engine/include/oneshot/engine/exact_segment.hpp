/// @file exact_segment.hpp
/// @brief The engine's one exact propagation step for a linear plant with held inputs:
///        state map, input map and cost Gramian of an interval from one Van Loan exponential,
///        cached per interval length, and the noise bridge of a state trace.
///
/// For ẋ = A x + B v with v (U columns) held over [0, Δ] and z = [e; v]:
///     e(Δ) = Φ(Δ) e + Γ(Δ) v,   ∫₀^Δ eᵀ Q1c e ds = zᵀ G(Δ) z,
/// from exp([[−Fᵀ, blkdiag(Q1c, 0)], [0, F]] Δ) = [[·, E12], [0, E22]] with F = [[A, B], [0, 0]]:
/// E22 = [[Φ, Γ], [0, I]] and G = E22ᵀ E12 (Van Loan, 1978).
///
/// A plant embedded in a larger shape (zero padded: a padded state has A, B, Q1c rows and
/// columns 0, a padded input a zero column of B; so has an absent disturbance, B_w = 0) has
/// decoupled indices j of F: F's row and column j and Q1c's are 0. There e^V is 1 on the
/// diagonal and 0 elsewhere, so the cache exponentiates the coupled indices only
/// (compact_exponential.hpp: the same operations, the zero block's terms left out) and puts
/// Φ = 1, Γ = 0, G = 0 at the decoupled ones: the padded plant's maps to the byte (tested
/// against dense_segment(), the exponential of the whole generator).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <unordered_map>
#include <vector>

#include "oneshot/assert_handler.hpp"
#include "oneshot/engine/compact_exponential.hpp"
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
    for (std::size_t j = 0; j < kK; ++j) {  // j is coupled unless F's and W's row and column j are 0
      bool zero = true;
      for (std::size_t i = 0; i < kK; ++i) zero = zero && f_(i, j) == 0 && f_(j, i) == 0 && w_(i, j) == 0 && w_(j, i) == 0;
      if (!zero) coupled_[coupled_n_++] = j;
    }
  }

  /// The number of coupled indices of z = [e; v] (kK for a plant that fills its shape).
  std::size_t coupled() const { return coupled_n_; }

  /// The map of an interval of `delta_ns` ns (> 0).
  const Segment& get(std::int64_t delta_ns) {
    const auto it = segments_.find(delta_ns);
    if (it != segments_.end()) return it->second;
    if (segments_.size() > capacity_) segments_.clear();
    const Segment s = coupled_n_ == kK ? dense_segment(delta_ns) : compact_segment(delta_ns);
    return segments_.emplace(delta_ns, s).first->second;
  }

  /// The map of an interval of `delta_ns` ns from the exponential of the whole generator V
  /// (every index, padded or not; not cached).
  Segment dense_segment(std::int64_t delta_ns) const {
    const Matrix<double, 2 * kK, 2 * kK> v = generator(delta_ns);
    Matrix<double, 2 * kK, 2 * kK> e;
    ONESHOT_ASSERT(matrix_exponential(v, e) == Status::kOk);
    return segment_of(e.template block<kK, kK, kK, kK>(), e.template block<0, kK, kK, kK>());
  }

  /// The same map from the exponential of V on the coupled indices only (not cached).
  Segment compact_segment(std::int64_t delta_ns) const {
    const Matrix<double, 2 * kK, 2 * kK> v = generator(delta_ns);
    const std::size_t c = coupled_n_;
    const std::size_t k = 2 * c;  // V's coupled indices: coupled_ in both halves
    const auto at = [&](std::size_t r) { return r < c ? coupled_[r] : kK + coupled_[r - c]; };
    std::array<double, 4 * kK * kK> vc{};
    std::array<double, 4 * kK * kK> ec{};
    for (std::size_t i = 0; i < k; ++i)
      for (std::size_t j = 0; j < k; ++j) vc[i * k + j] = v(at(i), at(j));
    ONESHOT_ASSERT(compact_exponential<2 * kK>(vc.data(), k, ec.data()) == Status::kOk);
    Matrix<double, kK, kK> e22 = Matrix<double, kK, kK>::identity();  // 1, 0 at the decoupled indices
    Matrix<double, kK, kK> e12;
    for (std::size_t i = 0; i < c; ++i)
      for (std::size_t j = 0; j < c; ++j) {
        e12(coupled_[i], coupled_[j]) = ec[i * k + c + j];
        e22(coupled_[i], coupled_[j]) = ec[(c + i) * k + c + j];
      }
    return segment_of(e22, e12);
  }

 private:
  /// V = [[−Fᵀ, W], [0, F]] Δ for an interval of `delta_ns` ns.
  Matrix<double, 2 * kK, 2 * kK> generator(std::int64_t delta_ns) const {
    const double d = static_cast<double>(delta_ns) * 1e-9;
    Matrix<double, 2 * kK, 2 * kK> v;
    v.template set_block<0, 0>(-(f_.transposed() * d));
    v.template set_block<0, kK>(w_ * d);
    v.template set_block<kK, kK>(f_ * d);
    return v;
  }
  /// Φ, Γ from E22 = [[Φ, Γ], [0, I]] and G = E22ᵀ E12.
  static Segment segment_of(const Matrix<double, kK, kK>& e22, const Matrix<double, kK, kK>& e12) {
    Segment s;
    s.phi = e22.template block<0, 0, N, N>();
    s.gamma = e22.template block<0, N, N, U>();
    s.g = e22.transposed() * e12;
    mirror_upper(s.g);
    return s;
  }

  Matrix<double, kK, kK> f_;
  Matrix<double, kK, kK> w_;
  std::size_t capacity_;
  std::array<std::size_t, kK> coupled_{};  ///< The coupled indices of z, ascending.
  std::size_t coupled_n_ = 0;              ///< Their count.
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
