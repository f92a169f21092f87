/// @file process_noise.hpp
/// @brief Continuous white process noise on a linear plant: exact per-interval draws, the
///        exact expected cost of the noise path, and bridge draws at intermediate instants.
///
/// For ẋ = A x + … + w, E[w(t) w(s)ᵀ] = Q_c δ(t − s), the noise accumulated over an interval
/// of length Δ started at zero is n(Δ) ~ N(0, Q_d(Δ)), Q_d(Δ) = ∫₀^Δ e^{As} Q_c e^{Aᵀs} ds,
/// computed by Van Loan: exp([[−A, Q_c], [0, Aᵀ]] Δ) = [[·, F₁₂], [0, F₂₂]], Q_d = F₂₂ᵀ F₁₂.
/// The cost receives the exact expectation of the noise path's own contribution,
///     E ∫₀^Δ nᵀ Q1c n ds = Σ_{k≥1} tr(Q1c M_k) Δ^{k+1}/(k+1)!,  M₁ = Q_c, M_{k+1} = A M_k + M_k Aᵀ
/// (Gauss–Legendre on ∫ tr(Q1c Q_d(s)) ds when ‖A‖Δ is large). Both are cached per interval
/// length (integer ns), the Cholesky factor with them.
///
/// Bridge: a recorder that wants the state at s inside an interval whose end noise n(Δ)
/// was already drawn takes n(a), a = s − t₀, from its conditional law
///     n(a) | n(Δ) ~ N(S Q_d(Δ)⁺ n(Δ), Q_d(a) − S Q_d(Δ)⁺ Sᵀ),  S = Q_d(a) Φ(Δ − a)ᵀ,
/// from its own random stream: the run's draws never depend on what is recorded.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <unordered_map>

#include "oneshot/assert_handler.hpp"
#include "oneshot/engine/psd_math.hpp"
#include "oneshot/engine/sim_time.hpp"
#include "oneshot/matrix.hpp"
#include "oneshot/matrix_exponential.hpp"
#include "oneshot/engine/random_stream.hpp"

namespace oneshot::engine {

/// White process noise of intensity Q_c on the states of ẋ = A x + ….
template <std::size_t N>
class ProcessNoise {
 public:
  /// Noise of intensity `qc` (state coordinates) on dynamics `a`; cost weight `q1c`; the cache
  /// per interval length is cleared when it passes `capacity` entries.
  ProcessNoise(const Matrix<double, N, N>& a, const Matrix<double, N, N>& qc, const Matrix<double, N, N>& q1c,
               std::size_t capacity = 4096)
      : a_(a), qc_(qc), capacity_(capacity) {
    Matrix<double, N, N> mk = qc;
    for (std::size_t k = 0; k < kTerms; ++k) {
      double tr = 0;
      const Matrix<double, N, N> prod = q1c * mk;
      for (std::size_t i = 0; i < N; ++i) tr += prod(i, i);
      coeff_[k] = tr;  // tr(Q1c M_{k+1})
      mk = a * mk + mk * a.transposed();
    }
    for (std::size_t j = 0; j < N; ++j) {
      double col = 0;
      for (std::size_t i = 0; i < N; ++i) col += std::fabs(a(i, j));
      a_norm_ = std::fmax(a_norm_, col);
    }
    q1c_ = q1c;
  }

  /// Q_d(Δ) (Van Loan, mirrored symmetric).
  Matrix<double, N, N> covariance(Duration delta) const {
    const double d = to_seconds(delta);
    Matrix<double, 2 * N, 2 * N> v;
    v.template set_block<0, 0>(-(a_ * d));
    v.template set_block<0, N>(qc_ * d);
    v.template set_block<N, N>(a_.transposed() * d);
    Matrix<double, 2 * N, 2 * N> f;
    ONESHOT_ASSERT(matrix_exponential(v, f) == Status::kOk);
    Matrix<double, N, N> q = f.template block<N, N, N, N>().transposed() * f.template block<0, N, N, N>();
    mirror_upper(q);
    return q;
  }

  /// Φ(Δ) = e^{AΔ}.
  Matrix<double, N, N> transition(Duration delta) const {
    Matrix<double, N, N> f;
    ONESHOT_ASSERT(matrix_exponential(a_ * to_seconds(delta), f) == Status::kOk);
    return f;
  }

  /// E ∫₀^Δ nᵀ Q1c n ds for the noise path started at 0.
  double expected_cost(Duration delta) const {
    const double d = to_seconds(delta);
    if (2 * a_norm_ * d <= 8) {
      double sum = 0;
      double power = d;  // Δ^{k+1}/(k+1)!
      for (std::size_t k = 0; k < kTerms; ++k) {
        power *= d / static_cast<double>(k + 2);
        const double term = coeff_[k] * power;
        sum += term;
        if (k > 4 && std::fabs(term) <= 1e-18 * std::fabs(sum)) break;
      }
      return sum;
    }
    // Gauss–Legendre on ∫₀^Δ tr(Q1c Q_d(s)) ds, 16 panels × 5 nodes.
    static constexpr double kX[5] = {-0.9061798459386640, -0.5384693101056831, 0.0, 0.5384693101056831,
                                     0.9061798459386640};
    static constexpr double kW[5] = {0.2369268850561891, 0.4786286704993665, 0.5688888888888889,
                                     0.4786286704993665, 0.2369268850561891};
    double sum = 0;
    const double hp = d / 16;
    for (int p = 0; p < 16; ++p)
      for (int k = 0; k < 5; ++k) {
        const double s = hp * (p + 0.5 + 0.5 * kX[k]);
        const Matrix<double, N, N> prod = q1c_ * covariance(Duration{std::llround(s * 1e9)});
        double tr = 0;
        for (std::size_t i = 0; i < N; ++i) tr += prod(i, i);
        sum += 0.5 * hp * kW[k] * tr;
      }
    return sum;
  }

  /// n(Δ) ~ N(0, Q_d(Δ)): the Cholesky factor (cached per Δ) times standard normals, the first
  /// `active` drawn (the others 0: a plant embedded in a larger shape, whose padded states have
  /// no noise, draws the numbers of its own shape; default all N).
  Vector<double, N> draw(Duration delta, RandomStream& rng, std::size_t active = N) {
    const Entry& e = entry(delta);
    Vector<double, N> w;
    for (std::size_t i = 0; i < active && i < N; ++i) w[i] = rng.normal();
    return e.chol * w;
  }

  /// The expected noise cost of an interval of length Δ (cached).
  double interval_cost(Duration delta) { return entry(delta).cost; }
  /// Q_d(Δ) (cached with the cost).
  const Matrix<double, N, N>& interval_covariance(Duration delta) { return entry(delta).qd; }

  /// n(a) given n(Δ) = `end` for a path started at 0 (0 < a ≤ Δ), from `rng` (its first
  /// `active` normals, as draw()).
  Vector<double, N> bridge(Duration a, Duration delta, const Vector<double, N>& end, RandomStream& rng,
                           std::size_t active = N) const {
    if (a >= delta) return end;
    const Matrix<double, N, N> qa = covariance(a);
    const Matrix<double, N, N> s = qa * transition(delta - a).transposed();
    const Matrix<double, N, N> gain = s * psd_pseudo_inverse(covariance(delta));
    Matrix<double, N, N> cov = qa - gain * s.transposed();
    mirror_upper(cov);
    Vector<double, N> z;
    for (std::size_t i = 0; i < active && i < N; ++i) z[i] = rng.normal();
    return gain * end + psd_cholesky(cov) * z;
  }

 /// Bytes of one cached interval length (Q_d, its factor and the expected cost).
  static constexpr std::size_t entry_bytes() { return sizeof(Entry); }

 private:
  static constexpr std::size_t kTerms = 40;
  struct Entry {
    Matrix<double, N, N> qd;
    Matrix<double, N, N> chol;
    double cost = 0;
  };
  const Entry& entry(Duration delta) {
    const auto it = cache_.find(delta.count());
    if (it != cache_.end()) return it->second;
    if (cache_.size() > capacity_) cache_.clear();
    Entry e;
    e.qd = covariance(delta);
    e.chol = psd_cholesky(e.qd);
    e.cost = expected_cost(delta);
    return cache_.emplace(delta.count(), e).first->second;
  }

  Matrix<double, N, N> a_;
  Matrix<double, N, N> qc_;
  Matrix<double, N, N> q1c_;
  double coeff_[kTerms] = {};
  double a_norm_ = 0;
  std::size_t capacity_;
  std::unordered_map<std::int64_t, Entry> cache_;
};

}  // namespace oneshot::engine
