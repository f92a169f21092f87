/// @file random_stream.hpp
/// @brief Seeded, named, reproducible random streams and the variates the engine draws.
///
/// Each stream is a std::mt19937_64 (a sequence fixed by the C++ standard) seeded from
/// (seed, stream name) through SplitMix64; every variate is computed here rather than by
/// <random>'s distributions, whose algorithms are unspecified, so a seed gives the same
/// numbers with any standard library. One stream per source (process noise, each
/// sensor's measurement noise, each link's delays and losses, jitter, set-points …, named
/// with stream_name()) keeps the sources independent: a run's draws from one source do
/// not move when another source draws more or less (common random numbers).
#pragma once

#include <cmath>
#include <cstdint>
#include <random>
#include <string>
#include <string_view>

namespace oneshot::engine {

/// SplitMix64 finaliser (bijective mixing of 64 bits).
constexpr std::uint64_t splitmix64(std::uint64_t x) {
  x += 0x9E3779B97F4A7C15ULL;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ULL;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBULL;
  return x ^ (x >> 31);
}

/// FNV-1a hash of a stream name.
constexpr std::uint64_t stream_id(std::string_view name) {
  std::uint64_t h = 0xCBF29CE484222325ULL;
  for (char c : name) h = (h ^ static_cast<unsigned char>(c)) * 0x100000001B3ULL;
  return h;
}

/// Stream name "a/b/c" from its parts (e.g. stream_name("link", "sc", "delay")).
inline std::string stream_name(std::string_view a, std::string_view b, std::string_view c = {}) {
  std::string s(a);
  s.append("/").append(b);
  if (!c.empty()) s.append("/").append(c);
  return s;
}

/// One independent random stream.
class RandomStream {
 public:
  /// Stream `name` of experiment seed `seed`.
  RandomStream(std::uint64_t seed, std::string_view name) : engine_(splitmix64(seed ^ splitmix64(stream_id(name)))) {}

  /// Uniform in [0, 1) with 53 random bits.
  double uniform01() { return static_cast<double>(engine_() >> 11) * 0x1.0p-53; }
  /// Uniform in [lo, hi).
  double uniform(double lo, double hi) { return lo + (hi - lo) * uniform01(); }
  /// Standard normal by the Marsaglia polar method.
  double normal() {
    if (has_spare_) {
      has_spare_ = false;
      return spare_;
    }
    double u = 0;
    double v = 0;
    double s = 0;
    do {
      u = 2 * uniform01() - 1;
      v = 2 * uniform01() - 1;
      s = u * u + v * v;
    } while (s >= 1 || s == 0);
    const double f = std::sqrt(-2 * std::log(s) / s);
    spare_ = v * f;
    has_spare_ = true;
    return u * f;
  }
  /// Uniform in (0, 1]: safe under a logarithm.
  double uniform01_open_low() { return 1.0 - uniform01(); }
  /// Integer uniform on [lo, hi] (hi ≥ lo, span below 2^53): ⌊u·(hi − lo + 1)⌋ + lo.
  std::int64_t uniform_int(std::int64_t lo, std::int64_t hi) {
    const double span = static_cast<double>(hi - lo) + 1.0;
    const auto k = static_cast<std::int64_t>(std::floor(uniform01() * span));
    return lo + (k > hi - lo ? hi - lo : k);
  }
  /// True with probability p (one uniform: u < p).
  bool bernoulli(double p) { return uniform01() < p; }
  /// Exponential with the given mean (inversion: −mean·ln U, U in (0, 1]).
  double exponential(double mean) { return -mean * std::log(uniform01_open_low()); }
  /// Poisson with the given mean by inversion of the cdf with one uniform
  /// (P(k) = P(k−1)·mean/k from P(0) = e^−mean); the mean must be below 700.
  std::int64_t poisson(double mean) {
    const double u = uniform01();
    double p = std::exp(-mean);
    double cdf = p;
    std::int64_t k = 0;
    while (u >= cdf && k < 100000) {
      ++k;
      p *= mean / static_cast<double>(k);
      cdf += p;
      if (p == 0.0 && static_cast<double>(k) > mean) break;  // cdf has reached 1 in double
    }
    return k;
  }
  /// Lognormal: exp(mu + sigma·Z), Z standard normal.
  double lognormal(double mu, double sigma) { return std::exp(mu + sigma * normal()); }
  /// Pareto (type I) with scale x_m and shape alpha: x_m·U^(−1/alpha), U in (0, 1].
  double pareto(double x_m, double alpha) { return x_m * std::pow(uniform01_open_low(), -1.0 / alpha); }

 private:
  std::mt19937_64 engine_;
  double spare_ = 0;
  bool has_spare_ = false;
};

}  // namespace oneshot::engine
