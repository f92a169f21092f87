/// @file scalar_traits.hpp
/// @brief The one point where a scalar type (float, double, fixed point) is described.
///
/// Templated core code never writes a floating literal: it asks ScalarTraits<S> for
/// constants (`zero()`, `one()`, `from_ratio()`), and mixes formats only through
/// `convert<To>()`, `mul<To>()` and Accumulator<To> (accumulator.hpp). Fixed-point
/// formats specialise the same templates in fixed_point.hpp.
#pragma once

#include <cstdint>
#include <type_traits>

namespace oneshot {

namespace detail {

/// Smallest Taylor degree m with θ^(m+1)/(m+1)! ≤ ε/2 for θ = 1/2, the scaled-norm
/// bound of matrix_exponential(): the truncation error is then below half an ulp.
constexpr int taylor_degree_for(double epsilon) {
  double term = 0.5;  // θ^1 / 1!
  int m = 0;
  while (term > epsilon / 2.0 && m < 30) {
    ++m;
    term = term * 0.5 / static_cast<double>(m + 1);  // θ^(m+1)/(m+1)!
  }
  return m;
}

}  // namespace detail

/// Description of a scalar type; specialised for every supported number format.
template <typename S, typename Enable = void>
struct ScalarTraits;

/// IEEE binary floating point (float, double).
template <typename F>
struct ScalarTraits<F, std::enable_if_t<std::is_floating_point_v<F>>> {
  static constexpr bool kIsFloating = true;
  /// Unit roundoff-sized bound used to pick series lengths.
  static constexpr double kEpsilon = std::is_same_v<F, float> ? 1.1920928955078125e-7
                                                              : 2.220446049250313e-16;
  /// Taylor degree of the scaled matrix exponential for this precision.
  static constexpr int kTaylorDegree = detail::taylor_degree_for(kEpsilon);
  /// Additive identity.
  static constexpr F zero() { return F(0); }
  /// Multiplicative identity.
  static constexpr F one() { return F(1); }
  /// num/den, correctly rounded when both are exactly representable.
  static constexpr F from_ratio(std::int64_t num, std::int64_t den) {
    return static_cast<F>(num) / static_cast<F>(den);
  }
  /// Exact for |v| < 2^24 (float) / 2^53 (double).
  static constexpr F from_int(std::int32_t v) { return static_cast<F>(v); }
  /// Rounds a double constant (compile-time data) into this format.
  static constexpr F from_double(double v) { return static_cast<F>(v); }
  /// Widening conversion for host-side checks and reports.
  static constexpr double to_double(F v) { return static_cast<double>(v); }
  /// |v|.
  static constexpr F abs(F v) { return v < F(0) ? -v : v; }
  /// Precomputed 1/den for fraction() (one division, at construction).
  using FractionScale = F;
  /// The scale of fraction(·, den).
  static constexpr FractionScale fraction_scale(std::int32_t den) { return from_ratio(1, den); }
  /// num/den for a run-time integer num (table residual r = δ/g): num·(1/den).
  static constexpr F fraction(std::int32_t num, FractionScale scale) { return from_int(num) * scale; }
  /// Nearest integer, halves away from zero; the caller keeps |v| < 2^31.
  static constexpr std::int32_t round_to_int(F v) {
    const F half = from_ratio(1, 2);
    return v < F(0) ? -static_cast<std::int32_t>(-v + half) : static_cast<std::int32_t>(v + half);
  }
};

/// Scalar holding an integer count (converter codes, τ in µs) next to format S:
/// S itself when floating, Fixed<int32_t, 0> for fixed point (fixed_point.hpp).
template <typename S, typename Enable = void>
struct CountScalar {
  using type = S;  ///< The count type.
  /// v as a count.
  static constexpr type make(std::int32_t v) { return static_cast<type>(v); }
};

/// v as the count type of format S.
template <typename S>
constexpr typename CountScalar<S>::type count_of(std::int32_t v) {
  return CountScalar<S>::make(v);
}

/// True for the built-in floating types, false for fixed point.
template <typename S>
inline constexpr bool kIsFloating = ScalarTraits<S>::kIsFloating;

/// Converts between scalar formats (floating specialisation; fixed point adds its own).
template <typename To, typename From>
constexpr std::enable_if_t<std::is_floating_point_v<To> && std::is_floating_point_v<From>, To>
convert(From v) {
  return static_cast<To>(v);
}

/// Product a·b delivered in format To (floating: computed in To).
template <typename To, typename A, typename B>
constexpr std::enable_if_t<std::is_floating_point_v<To> && std::is_floating_point_v<A> &&
                               std::is_floating_point_v<B>,
                           To>
mul(A a, B b) {
  return static_cast<To>(a) * static_cast<To>(b);
}

/// 1/v delivered in format To (floating: one correctly rounded division).
template <typename To, typename From>
constexpr std::enable_if_t<std::is_floating_point_v<To> && std::is_floating_point_v<From>, To>
reciprocal(From v) {
  return static_cast<To>(1) / static_cast<To>(v);
}

}  // namespace oneshot
