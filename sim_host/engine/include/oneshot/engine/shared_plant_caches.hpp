/// @file shared_plant_caches.hpp
/// @brief The caches a ContinuousPlant takes from a sweep's PlantCachePool, and the pool's
///        declaration: what the plant needs without the pool's locks and maps
///        (plant_cache_pool.hpp defines the pool; include it where a pool is made or passed).
#pragma once

#include <cstddef>
#include <memory>

namespace oneshot::engine {

template <std::size_t N, std::size_t U>
class ExactSegmentCache;
template <std::size_t N>
class ProcessNoise;
template <std::size_t N, std::size_t U>
class PlantCachePool;

/// The caches a plant takes from a pool (either may be null: the plant's own then).
template <std::size_t N, std::size_t U>
struct SharedPlantCaches {
  std::shared_ptr<ExactSegmentCache<N, U>> segments;  ///< Interval maps of (A, B held, Q1c).
  std::shared_ptr<ProcessNoise<N>> noise;             ///< Noise terms of (A, Q_c, Q1c).
};

}  // namespace oneshot::engine
