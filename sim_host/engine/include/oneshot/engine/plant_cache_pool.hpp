/// @file plant_cache_pool.hpp
/// @brief The exact interval maps and process-noise terms of a sweep's plants, shared by the
///        runs each thread of the sweep runs.
///
/// A run of a plant whose events fall at ever different offsets spends most of its time in
/// the Van Loan exponentials of new interval lengths (ExactSegmentCache, ProcessNoise), and
/// the runs of a sweep meet the same lengths again and again. Both caches memoize pure
/// functions of (plant, interval length in ns), so a run that takes its maps from a pool
/// computes the same bytes as one with its own caches.
///
/// Identity: the interval maps are keyed by the bytes of (A, B held, Q1c), the noise terms by
/// the bytes of (A, Q_c, Q1c) (a noise scale is part of Q_c): different plants never share.
/// Threads: each thread has its own shelf (taken under a mutex once per run and plant);
/// inside a run the caches are used without locks by the one thread that runs it.
/// Memory: per thread at most kPlantsPerThread caches of each kind (the least recently taken
/// one leaves the pool when a new plant needs a place; a run still holding it keeps it until
/// it ends), each cleared when it passes its entry count: about kCacheBytes of entries
/// (hash-node overhead counted), between kMinEntries and kMaxEntries interval lengths — at
/// most 2 · kPlantsPerThread · kCacheBytes ≈ 128 MiB per thread whatever N; all of it goes
/// with the pool, whose lifetime is the sweep's. A plant without process noise takes no
/// noise cache.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <map>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

#include "oneshot/engine/exact_segment.hpp"
#include "oneshot/engine/process_noise.hpp"
#include "oneshot/engine/shared_plant_caches.hpp"
#include "oneshot/matrix.hpp"

namespace oneshot::engine {

/// Per-thread caches of exact interval maps and noise terms, keyed by the plant's matrices.
template <std::size_t N, std::size_t U>
class PlantCachePool {
 public:
  static constexpr std::size_t kPlantsPerThread = 4;        ///< Caches of each kind kept per thread.
  static constexpr std::size_t kCacheBytes = std::size_t{16} << 20;  ///< Budget of one cache's entries.
  static constexpr std::size_t kMinEntries = 1024;          ///< Fewest interval lengths a cache keeps.
  static constexpr std::size_t kMaxEntries = 1u << 16;      ///< Most interval lengths a cache keeps.
  /// Interval lengths one cache keeps before it is cleared, for entries of `entry_bytes` (plus
  /// kNodeBytes of hash-table node each): kCacheBytes of them, within [kMinEntries, kMaxEntries].
  static constexpr std::size_t entries_for(std::size_t entry_bytes) {
    const std::size_t n = kCacheBytes / (entry_bytes + kNodeBytes);
    return n < kMinEntries ? kMinEntries : (n > kMaxEntries ? kMaxEntries : n);
  }
  /// Interval lengths per interval-map cache.
  static constexpr std::size_t segment_entries() { return entries_for(sizeof(ExactSegment<N, U>)); }
  /// Interval lengths per noise cache.
  static constexpr std::size_t noise_entries() { return entries_for(ProcessNoise<N>::entry_bytes()); }

  /// The calling thread's caches of the plant (A, B held, Q_c, Q1c), created on first use; no
  /// noise cache when `noisy` is false (the plant draws no process noise).
  SharedPlantCaches<N, U> take(const Matrix<double, N, N>& a, const Matrix<double, N, U>& b,
                               const Matrix<double, N, N>& qc, const Matrix<double, N, N>& q1c, bool noisy = true) {
    const std::lock_guard<std::mutex> lock(mutex_);
    Shelf& shelf = shelves_[std::this_thread::get_id()];
    ++shelf.clock;
    SharedPlantCaches<N, U> out;
    out.segments = find_or_add(shelf.segments, shelf.clock, key_of(a, b, q1c),
                               [&] { return std::make_shared<ExactSegmentCache<N, U>>(a, b, q1c, segment_entries()); });
    if (noisy) {
      out.noise = find_or_add(shelf.noise, shelf.clock, key_of(a, qc, q1c),
                              [&] { return std::make_shared<ProcessNoise<N>>(a, qc, q1c, noise_entries()); });
    }
    return out;
  }

  /// Caches held by the pool now, of both kinds, over every thread (for tests).
  std::size_t size() {
    const std::lock_guard<std::mutex> lock(mutex_);
    std::size_t n = 0;
    for (const auto& [id, shelf] : shelves_) n += shelf.segments.size() + shelf.noise.size();
    return n;
  }

 private:
  static constexpr std::size_t kNodeBytes = 48;  // an unordered_map node: key, links, hash
  using Key = std::vector<unsigned char>;
  template <typename T>
  struct Slot {
    Key key;
    std::uint64_t used = 0;
    std::shared_ptr<T> cache;
  };
  struct Shelf {
    std::uint64_t clock = 0;
    std::vector<Slot<ExactSegmentCache<N, U>>> segments;
    std::vector<Slot<ProcessNoise<N>>> noise;
  };

  /// The bytes of three matrices (bytes, not values: −0 and 0 are different plants here).
  template <std::size_t C>
  static Key key_of(const Matrix<double, N, N>& x, const Matrix<double, N, C>& y, const Matrix<double, N, N>& z) {
    Key k((2 * N * N + N * C) * sizeof(double));
    std::size_t at = 0;
    const auto put = [&](double v) {
      std::memcpy(k.data() + at, &v, sizeof v);
      at += sizeof v;
    };
    for (std::size_t i = 0; i < N; ++i)
      for (std::size_t j = 0; j < N; ++j) put(x(i, j));
    for (std::size_t i = 0; i < N; ++i)
      for (std::size_t j = 0; j < C; ++j) put(y(i, j));
    for (std::size_t i = 0; i < N; ++i)
      for (std::size_t j = 0; j < N; ++j) put(z(i, j));
    return k;
  }

  /// The cache of `key` on a shelf (marked used at `now`), made by make() when absent; the least
  /// recently used one leaves a full shelf first.
  template <typename T, typename Make>
  static std::shared_ptr<T> find_or_add(std::vector<Slot<T>>& slots, std::uint64_t now, Key key, Make make) {
    for (Slot<T>& s : slots) {
      if (s.key == key) {
        s.used = now;
        return s.cache;
      }
    }
    if (slots.size() >= kPlantsPerThread) {  // the least recently taken leaves
      std::size_t oldest = 0;
      for (std::size_t i = 1; i < slots.size(); ++i)
        if (slots[i].used < slots[oldest].used) oldest = i;
      slots.erase(slots.begin() + static_cast<std::ptrdiff_t>(oldest));
    }
    slots.push_back(Slot<T>{std::move(key), now, make()});
    return slots.back().cache;
  }

  std::mutex mutex_;
  std::map<std::thread::id, Shelf> shelves_;
};

}  // namespace oneshot::engine
