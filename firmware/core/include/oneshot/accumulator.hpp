/// @file accumulator.hpp
/// @brief Sum of products delivered in one output format.
///
/// Every dot product in the core goes through an Accumulator so that float, double and
/// fixed point share one code path. The floating version starts empty rather than at
/// zero: with software floating point an addition of 0 is a real library call, and the
/// structured kernels only feed the terms that are not structurally zero.
#pragma once

#include <type_traits>

#include "oneshot/scalar_traits.hpp"

namespace oneshot {

/// Accumulates Σ ±a·b and ±x into format Out; specialised per number format.
template <typename Out, typename Enable = void>
class Accumulator;

/// Floating accumulator: plain IEEE arithmetic in Out, left to right.
template <typename Out>
class Accumulator<Out, std::enable_if_t<std::is_floating_point_v<Out>>> {
 public:
  /// value += a·b.
  template <typename A, typename B>
  constexpr void add_product(A a, B b) { add(mul<Out>(a, b)); }
  /// value −= a·b.
  template <typename A, typename B>
  constexpr void sub_product(A a, B b) { sub(mul<Out>(a, b)); }
  /// value += x.
  template <typename X>
  constexpr void add(X x) {
    const Out v = convert<Out>(x);
    value_ = empty_ ? v : value_ + v;
    empty_ = false;
  }
  /// value −= x.
  template <typename X>
  constexpr void sub(X x) {
    const Out v = convert<Out>(x);
    value_ = empty_ ? -v : value_ - v;
    empty_ = false;
  }
  /// The sum (zero when nothing was added).
  constexpr Out value() const { return empty_ ? Out(0) : value_; }

 private:
  Out value_{};
  bool empty_ = true;
};

}  // namespace oneshot
