/// @file fixed_point.hpp
/// @brief Q-format fixed-point scalars: distinct types, saturating, rounding.
///
/// Fixed<Storage, F> holds value = raw · 2^−F in a 16- or 32-bit signed integer (F may
/// exceed the storage width for small quantities, or be negative for large ones). Every
/// operation rounds to nearest and saturates: arithmetic (products, format conversions,
/// Accumulator::value()) breaks ties upward, toward +∞ (round_shift: add half an LSB, shift);
/// conversions from outside (from_double, from_ratio) and round_to_int break them away from
/// zero, as std::lround. A saturation sets the sticky flag saturation_flag() that the
/// firmware can read and clear. Products of
/// two 16-bit formats are one 16×16→32 multiply; 32×16 products use two such multiplies
/// (exact, no 64-bit multiply routine); sums go through Accumulator's 64-bit register.
#pragma once

#include <cstdint>
#include <limits>
#include <type_traits>

#include "oneshot/accumulator.hpp"
#include "oneshot/scalar_traits.hpp"

#if defined(__STDC_HOSTED__) && __STDC_HOSTED__ && !defined(ONESHOT_NO_THREAD_LOCAL)
#define ONESHOT_STICKY_STORAGE thread_local
#else
#define ONESHOT_STICKY_STORAGE  // bare metal: one thread of control plus interrupts
#endif

namespace oneshot {

namespace detail {
/// The sticky saturation flag (one per thread on hosted builds).
inline ONESHOT_STICKY_STORAGE bool g_saturated = false;

/// 2^e as a double, e in [−126, 126] (constexpr, exact).
constexpr double pow2(int e) {
  double r = 1.0;
  for (int i = 0; i < e; ++i) r *= 2.0;
  for (int i = 0; i > e; --i) r *= 0.5;
  return r;
}

/// v · 2^−shift rounded to nearest, ties upward (the DSPs' conventional rounding: add
/// half an LSB, shift arithmetically; no branch on the sign); shift may be ≤ 0.
constexpr std::int64_t round_shift(std::int64_t v, int shift) {
  if (shift <= 0) return v * (std::int64_t{1} << -shift);  // callers keep this in range
  return (v + (std::int64_t{1} << (shift - 1))) >> shift;
}

/// v · 2^−shift rounded to nearest, ties away from zero (as std::lround: integer codes).
constexpr std::int64_t round_shift_away(std::int64_t v, int shift) {
  if (shift <= 0) return v * (std::int64_t{1} << -shift);
  const std::int64_t half = std::int64_t{1} << (shift - 1);
  return v >= 0 ? (v + half) >> shift : -((-v + half) >> shift);
}

/// v · 2^−shift rounded toward −∞ (shift may be ≤ 0): for terms entering an
/// accumulator with guard bits, where the final rounding is the one that counts.
constexpr std::int64_t floor_shift(std::int64_t v, int shift) {
  if (shift <= 0) return v * (std::int64_t{1} << -shift);
  return v >> shift;
}

/// v · 2^−shift for 32-bit v and 0 ≤ shift ≤ 31, rounded to nearest (ties upward),
/// without 64-bit arithmetic.
constexpr std::int32_t round_shift32(std::int32_t v, int shift) {
  if (shift == 0) return v;
  return ((v >> (shift - 1)) + 1) >> 1;
}

/// Clamps v into Storage, raising the sticky flag when it does not fit. The fit test
/// is one comparison: v fits when its narrowed value (GCC and Clang narrow modulo 2^n)
/// sign-extends back to v.
template <typename Storage>
constexpr Storage saturate(std::int64_t v) {
  const auto narrow = static_cast<Storage>(v);
  if (static_cast<std::int64_t>(narrow) == v) return narrow;
  g_saturated = true;
  return v > 0 ? std::numeric_limits<Storage>::max() : std::numeric_limits<Storage>::min();
}

/// Exact product of two 16-bit or 32-bit integers; 32×16 uses two 16×16 products.
template <typename A, typename B>
constexpr std::int64_t wide_product(A a, B b) {
  if constexpr (sizeof(A) <= 2 && sizeof(B) <= 2) {
    return static_cast<std::int32_t>(a) * static_cast<std::int32_t>(b);
  } else if constexpr (sizeof(A) == 4 && sizeof(B) <= 2) {
    const std::int32_t hi = (a >> 16) * static_cast<std::int32_t>(b);
    const std::int32_t lo = static_cast<std::int32_t>(static_cast<std::uint32_t>(a) & 0xFFFFU) * static_cast<std::int32_t>(b);
    return static_cast<std::int64_t>(hi) * 65536 + lo;
  } else if constexpr (sizeof(A) <= 2 && sizeof(B) == 4) {
    return wide_product(b, a);
  } else {
#if defined(__ARM_ARCH_6M__)
    // ARMv6-M has no 32×32→64 multiply; libgcc's 64×64 routine costs about twice these
    // four 16×16 products (each fits 32 bits: |high| ≤ 2^15, low < 2^16).
    const std::int32_t ah = a >> 16;
    const std::int32_t bh = b >> 16;
    const std::int32_t al = static_cast<std::int32_t>(static_cast<std::uint32_t>(a) & 0xFFFFU);
    const std::int32_t bl = static_cast<std::int32_t>(static_cast<std::uint32_t>(b) & 0xFFFFU);
    const std::int64_t middle = static_cast<std::int64_t>(ah * bl) + static_cast<std::int64_t>(al * bh);
    return static_cast<std::int64_t>(ah * bh) * (std::int64_t{1} << 32) + middle * 65536 +
           static_cast<std::int64_t>(static_cast<std::uint32_t>(al) * static_cast<std::uint32_t>(bl));
#else
    return static_cast<std::int64_t>(a) * static_cast<std::int64_t>(b);
#endif
  }
}
}  // namespace detail

/// True when a fixed-point operation has saturated since the last clear.
inline bool saturation_flag() { return detail::g_saturated; }
/// Clears the sticky saturation flag.
inline void clear_saturation_flag() { detail::g_saturated = false; }
/// Sets the sticky saturation flag (restores it around a scoped check).
inline void raise_saturation_flag() { detail::g_saturated = true; }

/// value = raw · 2^−kFrac, stored in Storage (int16_t or int32_t).
template <typename Storage, int kFracBits>
class Fixed {
  static_assert(std::is_same_v<Storage, std::int16_t> || std::is_same_v<Storage, std::int32_t>,
                "fixed-point storage is int16_t or int32_t");
  static_assert(kFracBits > -32 && kFracBits < 63, "fractional bits out of the supported range");

 public:
  using StorageType = Storage;                  ///< The integer holding the value.
  static constexpr int kFrac = kFracBits;       ///< Fractional bits.
  static constexpr int kBits = sizeof(Storage) * 8;  ///< Storage width.

  /// Like the built-in scalars: `Fixed x{}` is zero, `Fixed x;` is indeterminate, so a
  /// Matrix built with NoInit costs no zero fill (a memset call per matrix on an MCU).
  constexpr Fixed() = default;
  /// From a raw mantissa (the only way to read an integer as this format).
  static constexpr Fixed from_raw(Storage raw) {
    Fixed f{};
    f.raw_ = raw;
    return f;
  }
  /// The raw mantissa.
  constexpr Storage raw() const { return raw_; }

  /// Largest representable value.
  static constexpr double max_value() { return static_cast<double>(std::numeric_limits<Storage>::max()) * detail::pow2(-kFrac); }
  /// One unit in the last place.
  static constexpr double resolution() { return detail::pow2(-kFrac); }

  /// Saturating sum.
  friend constexpr Fixed operator+(Fixed a, Fixed b) {
    return from_raw(detail::saturate<Storage>(static_cast<std::int64_t>(a.raw_) + b.raw_));
  }
  /// Saturating difference.
  friend constexpr Fixed operator-(Fixed a, Fixed b) {
    return from_raw(detail::saturate<Storage>(static_cast<std::int64_t>(a.raw_) - b.raw_));
  }
  /// Saturating negation.
  friend constexpr Fixed operator-(Fixed a) { return from_raw(detail::saturate<Storage>(-static_cast<std::int64_t>(a.raw_))); }
  /// Rounded, saturating product in the same format.
  friend constexpr Fixed operator*(Fixed a, Fixed b) {
    return from_raw(detail::saturate<Storage>(detail::round_shift(detail::wide_product(a.raw_, b.raw_), kFrac)));
  }
  /// Ordering.
  friend constexpr bool operator<(Fixed a, Fixed b) { return a.raw_ < b.raw_; }
  /// Equality.
  friend constexpr bool operator==(Fixed a, Fixed b) { return a.raw_ == b.raw_; }

 private:
  Storage raw_;
};

/// T from a raw mantissa given as a wide integer (generated constants): saturates, so a
/// constant that does not fit fails constant evaluation instead of wrapping.
template <typename T>
constexpr T fixed_raw(std::int64_t raw) {
  return T::from_raw(detail::saturate<typename T::StorageType>(raw));
}

/// Q0.15 in 16 bits.
using Q15 = Fixed<std::int16_t, 15>;
/// Q0.31 in 32 bits.
using Q31 = Fixed<std::int32_t, 31>;

template <typename T>
struct IsFixed : std::false_type {};
template <typename S, int F>
struct IsFixed<Fixed<S, F>> : std::true_type {};
/// True for Fixed<…> types.
template <typename T>
inline constexpr bool kIsFixed = IsFixed<T>::value;

/// Description of a fixed-point format.
template <typename S, int F>
struct ScalarTraits<Fixed<S, F>> {
  using T = Fixed<S, F>;
  static constexpr bool kIsFloating = false;
  /// One unit in the last place relative to the format's unit range.
  static constexpr double kEpsilon = detail::pow2(-(T::kBits - 1));
  /// Taylor degree of the scaled exponential for this precision.
  static constexpr int kTaylorDegree = detail::taylor_degree_for(kEpsilon);
  /// Additive identity.
  static constexpr T zero() { return T{}; }
  /// 1 (saturates when the format cannot hold it). Integer arithmetic only: run-time
  /// calls (at -Og nothing is folded) must not pull soft-float routines into an MCU image.
  static constexpr T one() { return from_int(1); }
  /// v rounded into the format, saturated (constant data and host-side conversions).
  static constexpr T from_double(double v) {
    const double scaled = v * detail::pow2(F);
    const double r = scaled >= 0 ? scaled + 0.5 : scaled - 0.5;
    if (r >= static_cast<double>(std::numeric_limits<S>::max())) {
      detail::g_saturated = detail::g_saturated || r >= static_cast<double>(std::numeric_limits<S>::max()) + 1.0;
      return T::from_raw(std::numeric_limits<S>::max());
    }
    if (r <= static_cast<double>(std::numeric_limits<S>::min())) {
      detail::g_saturated = detail::g_saturated || r <= static_cast<double>(std::numeric_limits<S>::min()) - 1.0;
      return T::from_raw(std::numeric_limits<S>::min());
    }
    return T::from_raw(static_cast<S>(static_cast<std::int64_t>(r)));
  }
  /// num/den rounded to nearest (ties away from zero, as from_double), saturated; exact
  /// integer long division (no floating point, see one()). den = 0 saturates.
  static constexpr T from_ratio(std::int64_t num, std::int64_t den) {
    const bool negative = (num < 0) != (den < 0);
    const auto magnitude = [](std::int64_t v) {
      return v < 0 ? std::uint64_t{0} - static_cast<std::uint64_t>(v) : static_cast<std::uint64_t>(v);
    };
    const std::uint64_t n = magnitude(num);
    const std::uint64_t d = magnitude(den);
    // Any magnitude from 2^62 on saturates every storage: stop growing there.
    constexpr std::uint64_t kHuge = std::uint64_t{1} << 62;
    std::uint64_t q = d == 0 ? (n == 0 ? 0 : kHuge) : n / d;
    std::uint64_t rem = d == 0 ? 0 : n % d;
    bool round_up = false;
    if constexpr (F >= 0) {
      // q·2^F + rem/d, one fractional bit at a time (rem < d ≤ 2^63: 2·rem fits).
      for (int i = 0; d != 0 && i < F && q < kHuge; ++i) {
        rem *= 2;
        q = 2 * q + (rem >= d ? 1 : 0);
        if (rem >= d) rem -= d;
      }
      round_up = d != 0 && rem >= d - rem;  // rem/d ≥ 1/2
    } else {
      // round((q + rem/d) / 2^s): up when the dropped integer bits reach 2^(s−1).
      constexpr int kShift = -F;
      round_up = (q & ((std::uint64_t{1} << kShift) - 1)) >= (std::uint64_t{1} << (kShift - 1));
      q >>= kShift;
    }
    if (round_up) ++q;
    if (q > kHuge) q = kHuge;
    const auto v = static_cast<std::int64_t>(q);
    return T::from_raw(detail::saturate<S>(negative ? -v : v));
  }
  /// An integer, saturated.
  static constexpr T from_int(std::int32_t v) {
    return T::from_raw(detail::saturate<S>(F >= 0 ? static_cast<std::int64_t>(v) * (std::int64_t{1} << F)
                                                   : detail::round_shift(v, -F)));
  }
  /// The value as a double (host checks and reports).
  static constexpr double to_double(T v) { return static_cast<double>(v.raw()) * detail::pow2(-F); }
  /// |v| (saturating).
  static constexpr T abs(T v) { return v.raw() < 0 ? -v : v; }
  /// Nearest integer, halves away from zero (as std::lround on the floating formats).
  static constexpr std::int32_t round_to_int(T v) {
    return static_cast<std::int32_t>(detail::round_shift_away(v.raw(), F));
  }
  /// Precomputed 2^(F+16)/den for fraction() (one division, at construction).
  using FractionScale = std::uint32_t;
  /// The scale of fraction(·, den); 0 < den, F + 16 ≤ 31.
  static constexpr FractionScale fraction_scale(std::int32_t den) {
    static_assert(F >= 0 && F + 16 <= 31, "fraction() is for formats with at most 15 fractional bits");
    return static_cast<std::uint32_t>(((std::uint64_t{1} << (F + 16)) + static_cast<std::uint64_t>(den) / 2) /
                                      static_cast<std::uint64_t>(den));
  }
  /// num/den for 0 ≤ num < den: one 32-bit multiply and shift (error below one LSB).
  static constexpr T fraction(std::int32_t num, FractionScale scale) {
    const std::uint32_t raw = (static_cast<std::uint32_t>(num) * scale + 0x8000U) >> 16;
    return T::from_raw(detail::saturate<S>(static_cast<std::int64_t>(raw)));
  }
};

/// Counts next to a fixed format are plain integers in Q31.0.
template <typename S, int F>
struct CountScalar<Fixed<S, F>> {
  using type = Fixed<std::int32_t, 0>;  ///< The count type.
  /// v as a count.
  static constexpr type make(std::int32_t v) { return type::from_raw(v); }
};

/// Format conversion between fixed formats (rounded, saturated).
template <typename To, typename From>
constexpr std::enable_if_t<kIsFixed<To> && kIsFixed<From>, To> convert(From v) {
  return To::from_raw(detail::saturate<typename To::StorageType>(detail::round_shift(v.raw(), From::kFrac - To::kFrac)));
}

/// a·b in format To (exact product, one rounding, saturated).
template <typename To, typename A, typename B>
constexpr std::enable_if_t<kIsFixed<To> && kIsFixed<A> && kIsFixed<B>, To> mul(A a, B b) {
  return To::from_raw(detail::saturate<typename To::StorageType>(
      detail::round_shift(detail::wide_product(a.raw(), b.raw()), A::kFrac + B::kFrac - To::kFrac)));
}

/// 1/v in format To, to a relative precision of 2⁻¹⁶: v is normalised to a 16-bit
/// mantissa m·2^e and 2³¹/m is one 32-bit division (no 64-bit division routine on a
/// Cortex-M0). Saturates, raising the flag, for v ≤ 0 or a result out of range.
template <typename To, typename From>
constexpr std::enable_if_t<kIsFixed<To> && kIsFixed<From>, To> reciprocal(From v) {
  constexpr int kShift = To::kFrac + From::kFrac;
  static_assert(kShift >= 0 && kShift <= 62, "reciprocal formats need 0 ≤ F_to + F_from ≤ 62");
  if (v.raw() <= 0) {
    detail::g_saturated = true;
    return To::from_raw(std::numeric_limits<typename To::StorageType>::max());
  }
  // v.raw() = m · 2^e with m in [2^15, 2^16).
  std::uint32_t m = static_cast<std::uint32_t>(v.raw());
  int e = 0;
  while (m >= (1U << 16)) {
    m = (m + 1U) >> 1;
    ++e;
  }
  while (m < (1U << 15)) {
    m <<= 1;
    --e;
  }
  if (m >= (1U << 16)) {  // rounding carried over
    m >>= 1;
    ++e;
  }
  const std::uint32_t q = ((1U << 31) + m / 2) / m;  // 2^31/m in (2^15, 2^16]
  // 1/v · 2^kShift = q · 2^(kShift − 31 − e).
  return To::from_raw(detail::saturate<typename To::StorageType>(detail::round_shift(q, 31 + e - kShift)));
}

/// Fixed accumulator: 64-bit register with kGuard extra fractional bits over Out.
template <typename Out>
class Accumulator<Out, std::enable_if_t<kIsFixed<Out>>> {
 public:
  static constexpr int kGuard = 16;                 ///< Extra fractional bits kept.
  static constexpr int kAccFrac = Out::kFrac + kGuard;  ///< Fractional bits of the register.

  // Terms are truncated to the register's kAccFrac bits: with kGuard guard bits the
  // truncation error of a few terms stays far below the final rounding in value().

  /// value += a·b.
  template <typename A, typename B>
  constexpr void add_product(A a, B b) {
    acc_ += detail::floor_shift(detail::wide_product(a.raw(), b.raw()), A::kFrac + B::kFrac - kAccFrac);
  }
  /// value −= a·b.
  template <typename A, typename B>
  constexpr void sub_product(A a, B b) {
    acc_ -= detail::floor_shift(detail::wide_product(a.raw(), b.raw()), A::kFrac + B::kFrac - kAccFrac);
  }
  /// value += x.
  template <typename X>
  constexpr void add(X x) {
    acc_ += detail::floor_shift(x.raw(), X::kFrac - kAccFrac);
  }
  /// value −= x.
  template <typename X>
  constexpr void sub(X x) {
    acc_ -= detail::floor_shift(x.raw(), X::kFrac - kAccFrac);
  }
  /// The sum rounded into Out (saturated).
  constexpr Out value() const {
    return Out::from_raw(detail::saturate<typename Out::StorageType>(detail::round_shift(acc_, kGuard)));
  }

 private:
  std::int64_t acc_ = 0;
};

}  // namespace oneshot
