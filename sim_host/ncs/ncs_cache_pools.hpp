/// @file ncs_cache_pools.hpp
/// @brief A sweep's shared plant caches for every plant shape the loops run
///        (ONESHOT_NCS_SHAPES): one engine::PlantCachePool per shape.
///
/// A run takes its plant's interval maps and noise terms from the pool of its plant's shape
/// (RunOptions::caches, BasicHarness::caches()); the pools memoize pure functions of (plant,
/// interval length), so a run computes the same bytes with or without them. The holder is
/// generated from ONESHOT_NCS_SHAPES (a list of its Shape types): a shape added there gets its
/// pool here with no other change. Memory: each pool's own bound (plant_cache_pool.hpp) per thread, and only pools a
/// run took from hold caches (an empty pool is a mutex and an empty map).
#pragma once

#include <cstddef>
#include <tuple>
#include <utility>

#include "ncs_model.hpp"
#include "oneshot/engine/plant_cache_pool.hpp"

namespace oneshot::ncs {

namespace detail {
/// The index of the first shape of Shapes... with S's (n, m, p); sizeof...(Shapes) when none.
template <typename S, typename... Shapes>
constexpr std::size_t shape_index() {
  const bool same[] = {(Shapes::n == S::n && Shapes::m == S::m && Shapes::p == S::p)..., false};
  std::size_t i = 0;
  while (i < sizeof...(Shapes) && !same[i]) ++i;
  return i;
}
}  // namespace detail

/// The plant caches of a sweep, one PlantCachePool<n, m + 1> per shape of ONESHOT_NCS_SHAPES
/// (the held input and the set-point's input: m + 1 columns, as ContinuousPlant<n, m, p, 1>).
class ShapeCachePools {
#define ONESHOT_NCS_SHAPE_TYPE(n_, m_, p_) Shape<n_, m_, p_>,
  using Shapes = std::tuple<ONESHOT_NCS_SHAPES(ONESHOT_NCS_SHAPE_TYPE) void>;
#undef ONESHOT_NCS_SHAPE_TYPE
  // The macro's list ends with a comma: a void closes it, not a shape.
  static constexpr std::size_t kShapes = std::tuple_size_v<Shapes> - 1;

  template <std::size_t I>
  using ShapeAt = std::tuple_element_t<I, Shapes>;
  template <std::size_t... I>
  static auto pools_of(std::index_sequence<I...>)
      -> std::tuple<engine::PlantCachePool<ShapeAt<I>::n, ShapeAt<I>::m + 1>...>;
  template <typename S, std::size_t... I>
  static constexpr std::size_t index_of(std::index_sequence<I...>) {
    return detail::shape_index<S, ShapeAt<I>...>();
  }

 public:
  /// The pool of the plants of shape S (Shape<n, m, p>); nullptr for a shape not listed in
  /// ONESHOT_NCS_SHAPES (its runs keep their own caches).
  template <typename S>
  engine::PlantCachePool<S::n, S::m + 1>* pool() {
    constexpr std::size_t i = index_of<S>(std::make_index_sequence<kShapes>{});
    if constexpr (i < kShapes) {
      return &std::get<i>(pools_);
    } else {
      return nullptr;
    }
  }

  /// Caches held now over every shape and thread (PlantCachePool::size(); for tests).
  std::size_t size() {
    return std::apply([](auto&... p) { return (std::size_t{0} + ... + p.size()); }, pools_);
  }

 private:
  decltype(pools_of(std::make_index_sequence<kShapes>{})) pools_;
};

}  // namespace oneshot::ncs
