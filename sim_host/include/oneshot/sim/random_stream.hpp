/// @file random_stream.hpp
/// @brief Seeded, named, reproducible random streams.
///
/// Each stream is a std::mt19937_64 (a sequence fixed by the C++ standard) seeded from
/// (seed, stream name) through SplitMix64; uniform and normal variates are computed
/// here rather than by <random>'s distributions, whose algorithms are unspecified, so a
/// seed gives the same numbers with any standard library.
#pragma once

#include <cmath>
#include <cstdint>
#include <random>
#include <string_view>

namespace oneshot::sim {

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

 private:
  std::mt19937_64 engine_;
  double spare_ = 0;
  bool has_spare_ = false;
};

}  // namespace oneshot::sim
