/// @file ncs_cache_pools.hpp
/// @brief A sweep's shared plant caches for every plant shape the loops run
///        (ONESHOT_NCS_SHAPES): one engine::PlantCachePool per shape.
///
/// A run takes its plant's interval maps and noise terms from the pool of its plant's shape
/// (RunOptions::caches, BasicHarness::caches()); the pools memoize pure functions of (plant,
/// interval length), so a run computes the same bytes with or without them. The holder is
/// generated from ONESHOT_NCS_SHAPES: a shape added there gets its pool here with no other
/// change. Memory: each pool's own bound (plant_cache_pool.hpp) per thread, and only pools a
/// run took from hold caches (an empty pool is a mutex and an empty map).
#pragma once

#include <cstddef>

#include "ncs_model.hpp"
#include "oneshot/engine/plant_cache_pool.hpp"

namespace oneshot::ncs {

/// The plant caches of a sweep, one PlantCachePool<n, m + 1> per shape of ONESHOT_NCS_SHAPES
/// (the held input and the set-point's input: m + 1 columns, as ContinuousPlant<n, m, p, 1>).
class ShapeCachePools {
 public:
  /// The pool of the plants of shape S (Shape<n, m, p>); nullptr for a shape not listed in
  /// ONESHOT_NCS_SHAPES (its runs keep their own caches).
  template <typename S>
  engine::PlantCachePool<S::n, S::m + 1>* pool() {
#define ONESHOT_NCS_POOL_OF(n_, m_, p_) \
  if constexpr (S::n == (n_) && S::m == (m_) && S::p == (p_)) return &pool_##n_##_##m_##_##p_##_; else
    ONESHOT_NCS_SHAPES(ONESHOT_NCS_POOL_OF) return nullptr;
#undef ONESHOT_NCS_POOL_OF
  }

  /// Caches held now over every shape and thread (PlantCachePool::size(); for tests).
  std::size_t size() {
    std::size_t n = 0;
#define ONESHOT_NCS_POOL_SIZE(n_, m_, p_) n += pool_##n_##_##m_##_##p_##_.size();
    ONESHOT_NCS_SHAPES(ONESHOT_NCS_POOL_SIZE)
#undef ONESHOT_NCS_POOL_SIZE
    return n;
  }

 private:
#define ONESHOT_NCS_POOL_MEMBER(n_, m_, p_) engine::PlantCachePool<(n_), (m_) + 1> pool_##n_##_##m_##_##p_##_;
  ONESHOT_NCS_SHAPES(ONESHOT_NCS_POOL_MEMBER)
#undef ONESHOT_NCS_POOL_MEMBER
};

}  // namespace oneshot::ncs
