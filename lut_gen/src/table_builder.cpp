/// @file table_builder.cpp
/// @brief Table construction and accuracy measurement (see table_builder.hpp).
#include "oneshot/design/table_builder.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <type_traits>
#include <utility>
#include <limits>
#include <stdexcept>
#include <string>

#include "oneshot/design/dimension_dispatch.hpp"
#include "oneshot/design/fixed_size.hpp"
#include "oneshot/generic_discretizer.hpp"
#include "oneshot/plant_structure.hpp"
#include "oneshot/table_discretizer.hpp"

namespace oneshot::design {
namespace {

using F64 = UniformFormat<double>;

/// One free matrix entry as a function of t: its grid values and Taylor coefficients.
struct Candidate {
  enum class Kind { kPhi, kGamma, kQd } kind;
  std::size_t i, j;
  std::vector<double> grid;    // value at i·g, i = 1 … max_index
  std::vector<double> coeffs;  // Taylor coefficient of r^k, k = 0 …
};

/// Trailing-coefficient cut: terms below eps/16 of the largest do not change the result.
std::pair<std::size_t, std::size_t> trim(const std::vector<double>& c, double eps) {
  double biggest = 0;
  for (double v : c) biggest = std::max(biggest, std::fabs(v));
  if (biggest == 0) return {0, 0};
  std::size_t high = c.size() - 1;
  while (high > 0 && std::fabs(c[high]) < eps / 16 * biggest) --high;
  std::size_t low = 0;
  while (low < high && c[low] == 0) ++low;
  return {low, high};
}

/// One slot rounded into storage S: values, residual polynomial, scales, errors.
template <typename S>
struct RoundedSlot {
  using Value = typename TableElements<S>::Value;
  using Coefficient = typename TableElements<S>::Coefficient;
  std::vector<Value> grid;
  std::uint8_t low = 0, high = 0;
  std::vector<Coefficient> coeffs;  // low … high
  std::int8_t value_frac = 0, residual_frac = 0;
  double error_abs = 0, error_rel = 0;
};

template <typename T>
bool same_raw(const std::vector<T>& a, const std::vector<T>& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i) {
    if constexpr (std::is_floating_point_v<T>) {
      if (!(a[i] == b[i])) return false;
    } else {
      if (a[i].raw != b[i].raw) return false;
    }
  }
  return true;
}

template <typename S>
bool same(const RoundedSlot<S>& a, const RoundedSlot<S>& b) {
  return a.low == b.low && a.high == b.high && a.value_frac == b.value_frac && a.residual_frac == b.residual_frac &&
         same_raw(a.grid, b.grid) && same_raw(a.coeffs, b.coeffs);
}

template <typename S>
RoundedSlot<S> round_slot(const std::vector<double>& grid, const std::vector<double>& coeffs) {
  RoundedSlot<S> r;
  double scale = 0;
  for (double v : grid) scale = std::max(scale, std::fabs(v));
  const auto note = [&](double exact, double stored) {
    r.error_abs = std::max(r.error_abs, std::fabs(exact - stored));
    if (scale > 0) r.error_rel = std::max(r.error_rel, std::fabs(exact - stored) / scale);
  };
  if constexpr (std::is_floating_point_v<S>) {
    for (double v : grid) {
      r.grid.push_back(static_cast<S>(v));
      note(v, static_cast<double>(r.grid.back()));
    }
    std::vector<double> rounded;
    for (double v : coeffs) rounded.push_back(static_cast<double>(static_cast<S>(v)));
    const auto [low, high] = trim(rounded, ScalarTraits<S>::kEpsilon);
    r.low = static_cast<std::uint8_t>(low);
    r.high = static_cast<std::uint8_t>(high);
    for (std::size_t k = low; k <= high; ++k) r.coeffs.push_back(static_cast<S>(rounded[k]));
  } else {
    // 16-bit values at the largest scale that holds the slot; 32-bit coefficients at the
    // largest scale holding Σ|c| (a bound on every Horner partial sum, r < 1).
    const auto frac_for = [](double range, int bits) {
      int e = 0;
      std::frexp(range > 0 ? range : 1.0, &e);
      int frac = bits - 1 - e;
      while (std::ldexp(range, frac) > std::ldexp(1.0, bits - 1) - 1) --frac;
      return frac;
    };
    r.value_frac = static_cast<std::int8_t>(std::clamp(frac_for(scale, 16), -31, 62));
    for (double v : grid) {
      const double raw = std::round(std::ldexp(v, r.value_frac));
      r.grid.push_back(Mantissa16{static_cast<std::int16_t>(raw)});
      note(v, std::ldexp(raw, -r.value_frac));
    }
    const auto [low, high] = trim(coeffs, std::ldexp(1.0, -31));
    double sum = 0;
    for (std::size_t k = low; k <= high; ++k) sum += std::fabs(coeffs[k]);
    r.residual_frac = static_cast<std::int8_t>(std::clamp(frac_for(1.01 * sum, 32), -31, 62));
    r.low = static_cast<std::uint8_t>(low);
    r.high = static_cast<std::uint8_t>(high);
    for (std::size_t k = low; k <= high; ++k) {
      const double raw = std::round(std::ldexp(coeffs[k], r.residual_frac));
      r.coeffs.push_back(Mantissa32{static_cast<std::int32_t>(raw)});
      note(coeffs[k], std::ldexp(raw, -r.residual_frac));
    }
  }
  return r;
}

struct Layout {
  std::vector<std::uint16_t> radix;  // per level, finest first
  std::size_t entries = 0;
  std::size_t bytes = 0;
};

/// Entries of a radix vector covering indices 0 … max_index; 0 when a level is unused.
std::size_t layout_entries(const std::vector<std::size_t>& radix_below_top, std::size_t max_index,
                           std::vector<std::uint16_t>& radix_out) {
  std::size_t spacing = 1;
  std::size_t entries = 0;
  radix_out.clear();
  for (std::size_t r : radix_below_top) {
    entries += r - 1;
    radix_out.push_back(static_cast<std::uint16_t>(r));
    spacing *= r;
    if (spacing > max_index) return 0;  // level above would be empty
  }
  const std::size_t top_digits = max_index / spacing;
  if (top_digits + 1 > std::numeric_limits<std::uint16_t>::max()) return 0;
  radix_out.push_back(static_cast<std::uint16_t>(top_digits + 1));
  return entries + top_digits;
}

template <typename S, std::size_t N, std::size_t M>
TableData<S> build_fixed(const PlantDescription& plant, const DesignResult& design, const PlantPatterns& patterns) {
  const GenericDiscretizer<F64, N, M> generic(continuous_model_per_us<double, N, M>(plant, design));
  const std::int32_t g = plant.table_granularity_us;
  const std::size_t max_index = static_cast<std::size_t>(plant.table_range_us / g);
  std::vector<Discretization<F64, N, M>> grid(max_index + 1);
  for (std::size_t i = 1; i <= max_index; ++i) {
    if (generic.discretize(static_cast<std::int32_t>(i) * g, grid[i], WithQd::kYes) != Status::kOk) {
      throw DesignError("table: the matrix exponential fails at t = " + std::to_string(i * static_cast<std::size_t>(g)) +
                        " us (reduce table.range_us)");
    }
  }

  // Taylor degree K: (2‖A‖₁g)^(K+1)/(K+1)! ≤ ε/4 bounds the relative truncation error.
  constexpr double kStorageEpsilon = std::is_floating_point_v<S> ? ScalarTraits<std::conditional_t<std::is_floating_point_v<S>, S, double>>::kEpsilon
                                                                 : 0x1.0p-31;
  const double g_s = static_cast<double>(g) * 1e-6;
  const auto a = to_fixed<double, N, N>(plant.a);
  const auto b = to_fixed<double, N, M>(plant.b);
  const auto qc = to_fixed<double, N, N>(design.qc);
  double norm_a = 0;
  for (std::size_t j = 0; j < N; ++j) {
    double col = 0;
    for (std::size_t i = 0; i < N; ++i) col += std::fabs(a(i, j));
    norm_a = std::max(norm_a, col);
  }
  const double x = 2 * norm_a * g_s;
  int degree = 1;
  double term = x * x / 2;  // x^(K+1)/(K+1)! for K = degree
  while (term > kStorageEpsilon / 4 && degree < 30) {
    ++degree;
    term *= x / (degree + 1);
  }
  // Coefficients of r^k: Φ: (Ag)^k/k!; Γ: (Ag)^k B g/(k+1)! at r^(k+1); Q_d: M_k g^k/k!,
  // M_1 = Q_c, M_{k+1} = A M_k + M_k Aᵀ.
  const std::size_t terms = static_cast<std::size_t>(degree) + 2;
  std::vector<Matrix<double, N, N>> phi_c(terms);
  std::vector<Matrix<double, N, M>> gamma_c(terms);
  std::vector<Matrix<double, N, N>> qd_c(terms);
  Matrix<double, N, N> power = Matrix<double, N, N>::identity();  // (Ag)^k / k!
  Matrix<double, N, N> mk = qc;
  double gk = g_s;  // g^k / k!
  for (std::size_t k = 0; k < terms; ++k) {
    phi_c[k] = power;
    if (k + 1 < terms) gamma_c[k + 1] = power * b * (g_s / static_cast<double>(k + 1));
    if (k >= 1) {
      qd_c[k] = mk * gk;
      mk = a * mk + mk * a.transposed();
      gk *= g_s / static_cast<double>(k + 1);
    }
    power = a * power * (g_s / static_cast<double>(k + 1));
  }

  // Free entries, Φ and Γ first.
  std::vector<Candidate> cands;
  auto add = [&](Candidate::Kind kind, std::size_t i, std::size_t j, auto value_of, auto coeff_of) {
    Candidate c{kind, i, j, {}, {}};
    for (std::size_t t = 1; t <= max_index; ++t) c.grid.push_back(value_of(grid[t]));
    for (std::size_t k = 0; k < terms; ++k) c.coeffs.push_back(coeff_of(k));
    cands.push_back(std::move(c));
  };
  for (std::size_t i = 0; i < N; ++i)
    for (std::size_t j = 0; j < N; ++j)
      if (patterns.phi.is_free(i, j))
        add(Candidate::Kind::kPhi, i, j, [&](const auto& d) { return d.phi(i, j); }, [&](std::size_t k) { return phi_c[k](i, j); });
  for (std::size_t i = 0; i < N; ++i)
    for (std::size_t j = 0; j < M; ++j)
      if (patterns.gamma.is_free(i, j))
        add(Candidate::Kind::kGamma, i, j, [&](const auto& d) { return d.gamma(i, j); }, [&](std::size_t k) { return gamma_c[k](i, j); });
  for (std::size_t i = 0; i < N; ++i)
    for (std::size_t j = i; j < N; ++j)
      if (patterns.qd.is_free(i, j))
        add(Candidate::Kind::kQd, i, j, [&](const auto& d) { return d.qd(i, j); }, [&](std::size_t k) { return qd_c[k](i, j); });

  TableData<S> t;
  t.n = N;
  t.m = M;
  t.granularity_us = g;
  t.range_us = plant.table_range_us;
  t.phi_slot.assign(N * N, kSlotZero);
  t.gamma_slot.assign(N * M, kSlotZero);
  t.qd_slot.assign(N * N, kSlotZero);
  for (std::size_t i = 0; i < N; ++i)
    for (std::size_t j = 0; j < N; ++j)
      if (patterns.phi.is_one(i, j)) t.phi_slot[i * N + j] = kSlotOne;

  // Slots: identical rounded grid values and polynomial share one.
  std::vector<RoundedSlot<S>> slots;
  bool in_transition = true;
  for (const Candidate& c : cands) {
    if (c.kind == Candidate::Kind::kQd && in_transition) {
      t.transition_slots = static_cast<std::uint16_t>(slots.size());
      in_transition = false;
    }
    const RoundedSlot<S> rs = round_slot<S>(c.grid, c.coeffs);
    std::size_t index = 0;
    while (index < slots.size() && !same(slots[index], rs)) ++index;
    if (index == slots.size()) slots.push_back(rs);
    if (slots.size() > max_table_slots(N, M)) throw DesignError("table: more free entries than max_table_slots");
    const auto code = static_cast<std::int16_t>(index);
    if (c.kind == Candidate::Kind::kPhi) t.phi_slot[c.i * N + c.j] = code;
    if (c.kind == Candidate::Kind::kGamma) t.gamma_slot[c.i * M + c.j] = code;
    if (c.kind == Candidate::Kind::kQd) t.qd_slot[c.i * N + c.j] = t.qd_slot[c.j * N + c.i] = code;
  }
  if (in_transition) t.transition_slots = static_cast<std::uint16_t>(slots.size());
  t.slots = static_cast<std::uint16_t>(slots.size());
  constexpr bool kBlock = std::is_same_v<S, BlockFixedStorage>;
  for (const RoundedSlot<S>& rs : slots) {
    t.residual_low.push_back(rs.low);
    t.residual_high.push_back(rs.high);
    t.residual_offset.push_back(static_cast<std::uint16_t>(t.residual_coefficients.size()));
    t.residual_coefficients.insert(t.residual_coefficients.end(), rs.coeffs.begin(), rs.coeffs.end());
    if constexpr (kBlock) {
      t.value_frac.push_back(rs.value_frac);
      t.residual_frac.push_back(rs.residual_frac);
    }
    t.quantization_abs = std::max(t.quantization_abs, rs.error_abs);
    t.quantization_rel = std::max(t.quantization_rel, rs.error_rel);
  }
  // 8-bit tables (SlotIdFor) index coefficients in 8 bits, 16-bit tables in 16.
  const std::size_t max_coefficients = t.narrow_slots() ? 255 : 65535;
  if (t.residual_coefficients.size() > max_coefficients) {
    throw DesignError("table: " + std::to_string(t.residual_coefficients.size()) + " residual coefficients exceed the " +
                      std::to_string(max_coefficients) + " a " + (t.narrow_slots() ? "8" : "16") +
                      "-bit-indexed table addresses");
  }
  if (t.narrow_slots()) {
    const auto narrow = [](const std::vector<std::int16_t>& v) { return std::vector<std::int8_t>(v.begin(), v.end()); };
    t.phi_slot8 = narrow(t.phi_slot);
    t.gamma_slot8 = narrow(t.gamma_slot);
    t.qd_slot8 = narrow(t.qd_slot);
    for (std::uint16_t o : t.residual_offset) t.residual_offset8.push_back(static_cast<std::uint8_t>(o));
  }
  const std::size_t slot_id_bytes = t.narrow_slots() ? 1 : 2;
  using Value = typename TableData<S>::Value;
  using Coefficient = typename TableData<S>::Coefficient;

  // Layout: fewest levels that fit table.max_bytes, then fewest bytes.
  const std::size_t fixed_bytes = sizeof(Coefficient) * t.residual_coefficients.size() +
                                  slot_id_bytes * (2 * N * N + N * M) + (2U + slot_id_bytes) * t.slots +
                                  (kBlock ? 2U * t.slots : 0U);
  const auto cost = [&](std::size_t entries, std::size_t levels) {
    return fixed_bytes + sizeof(Value) * entries * t.slots + 4 * levels;
  };
  // table.max_bytes budgets 4-byte values (the float firmware table); doubles get twice.
  const std::size_t budget = static_cast<std::size_t>(plant.table_max_bytes) * std::max<std::size_t>(1, sizeof(Value) / 4);
  Layout best;
  std::size_t smallest = std::numeric_limits<std::size_t>::max();
  const auto consider = [&](const std::vector<std::size_t>& below) {
    std::vector<std::uint16_t> radix;
    const std::size_t entries = layout_entries(below, max_index, radix);
    if (entries == 0) return;
    const std::size_t bytes = cost(entries, radix.size());
    smallest = std::min(smallest, bytes);
    if (bytes <= budget && (best.radix.empty() || bytes < best.bytes)) {
      best = Layout{radix, entries, bytes};
    }
  };
  // Radix vectors below the top level, product ≤ max_index, by increasing level count.
  std::vector<std::size_t> below;
  const std::function<void(std::size_t, std::size_t)> enumerate = [&](std::size_t depth, std::size_t product) {
    if (depth == 0) {
      consider(below);
      return;
    }
    for (std::size_t r = 2; product * r <= max_index; ++r) {
      below.push_back(r);
      enumerate(depth - 1, product * r);
      below.pop_back();
    }
  };
  for (std::size_t levels = 1; levels <= 4 && best.radix.empty(); ++levels) enumerate(levels - 1, 1);
  if (best.radix.empty()) {
    throw DesignError("table.max_bytes: " + std::to_string(budget) + " bytes of " + std::to_string(sizeof(Value)) +
                      "-byte values is too small; the smallest layout of up to 4 levels needs " +
                      std::to_string(smallest) + " bytes");
  }
  t.radix = best.radix;
  std::size_t spacing = 1;
  for (std::size_t l = 0; l < t.radix.size(); ++l) {
    t.level_offset.push_back(static_cast<std::uint16_t>(t.entry_time_us.size()));
    const std::size_t digits = l + 1 < t.radix.size() ? t.radix[l] - 1U : max_index / spacing;
    for (std::size_t d = 1; d <= digits; ++d) {
      const std::size_t index = d * spacing;
      t.entry_time_us.push_back(static_cast<std::int32_t>(index) * g);
      std::vector<Value> entry(t.slots);
      for (std::size_t s = 0; s < t.slots; ++s) entry[s] = slots[s].grid[index - 1];
      t.values.insert(t.values.end(), entry.begin(), entry.end());
    }
    spacing *= t.radix[l];
  }
  return t;
}

template <typename S, std::size_t N, std::size_t M>
TableAccuracy accuracy_fixed(const TableData<S>& table, const PlantDescription& plant, const DesignResult& design) {
  using Fmt = UniformFormat<S>;
  const GenericDiscretizer<F64, N, M> generic(continuous_model_per_us<double, N, M>(plant, design));
  const TableView<S> view = table.view();
  const TableDiscretizer<Fmt, DenseStructure<N, M, 1>, S> lut(view);
  const std::int32_t g = table.granularity_us;
  std::vector<std::int32_t> taus;
  for (std::int32_t t = 0; t <= table.range_us; t += g) {
    taus.push_back(t);
    if (t + g / 2 <= table.range_us) taus.push_back(t + g / 2);
  }
  const std::int32_t step = std::max<std::int32_t>(1, g * 7 / 13);
  for (std::int32_t t = 1; t <= 2 * table.range_us; t += step) taus.push_back(t);
  TableAccuracy acc;
  for (std::int32_t tau : taus) {
    Discretization<F64, N, M> ref;
    Discretization<Fmt, N, M> got;
    if (generic.discretize(tau, ref, WithQd::kYes) != Status::kOk) continue;
    const Status looked_up = lut.discretize(tau, got, WithQd::kYes);
    if (looked_up != Status::kOk && looked_up != Status::kExtended) {  // beyond the range: composed, still exact
      throw std::runtime_error("table accuracy: the table failed at tau = " + std::to_string(tau) + " us");
    }
    const auto compare = [](const auto& r, const auto& v, double& abs_max, double& rel_max) {
      double scale = 0;
      double err = 0;
      for (std::size_t k = 0; k < r.kSize; ++k) {
        scale = std::max(scale, std::fabs(r[k]));
        err = std::max(err, std::fabs(r[k] - static_cast<double>(v[k])));
      }
      abs_max = std::max(abs_max, err);
      if (scale > 0) rel_max = std::max(rel_max, err / scale);
    };
    compare(ref.phi, got.phi, acc.phi_abs, acc.phi_rel);
    compare(ref.gamma, got.gamma, acc.gamma_abs, acc.gamma_rel);
    compare(ref.qd, got.qd, acc.qd_abs, acc.qd_rel);
    ++acc.points;
  }
  acc.max_abs_error = std::max({acc.phi_abs, acc.gamma_abs, acc.qd_abs});
  return acc;
}

}  // namespace

template <typename S>
TableData<S> build_table(const PlantDescription& plant, const DesignResult& design, const PlantPatterns& patterns) {
  return with_dimensions(plant.n(), plant.m(), 1, [&](auto n, auto m, auto) {
    return build_fixed<S, decltype(n)::value, decltype(m)::value>(plant, design, patterns);
  });
}

template <typename S>
TableAccuracy measure_accuracy(const TableData<S>& table, const PlantDescription& plant, const DesignResult& design) {
  return with_dimensions(plant.n(), plant.m(), 1, [&](auto n, auto m, auto) {
    return accuracy_fixed<S, decltype(n)::value, decltype(m)::value>(table, plant, design);
  });
}

template TableData<float> build_table<float>(const PlantDescription&, const DesignResult&, const PlantPatterns&);
template TableData<BlockFixedStorage> build_table<BlockFixedStorage>(const PlantDescription&, const DesignResult&,
                                                                     const PlantPatterns&);
template TableData<double> build_table<double>(const PlantDescription&, const DesignResult&, const PlantPatterns&);
template TableAccuracy measure_accuracy<float>(const TableData<float>&, const PlantDescription&, const DesignResult&);
template TableAccuracy measure_accuracy<double>(const TableData<double>&, const PlantDescription&, const DesignResult&);

}  // namespace oneshot::design
