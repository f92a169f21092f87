/// @file table_builder.cpp
/// @brief Table construction and accuracy measurement (see table_builder.hpp).
#include "oneshot/design/table_builder.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
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

/// Rounded, trimmed polynomial of a candidate in storage format S.
template <typename S>
struct Polynomial {
  std::uint8_t low = 0, high = 0;
  std::vector<S> coeffs;  // low … high
  bool operator==(const Polynomial& o) const { return low == o.low && high == o.high && coeffs == o.coeffs; }
};

template <typename S>
Polynomial<S> trimmed(const std::vector<double>& c) {
  std::vector<S> rounded;
  for (double v : c) rounded.push_back(static_cast<S>(v));
  double biggest = 0;
  for (S v : rounded) biggest = std::max(biggest, std::fabs(static_cast<double>(v)));
  Polynomial<S> p;
  if (biggest == 0) {
    p.coeffs = {S(0)};
    return p;
  }
  const double eps = ScalarTraits<S>::kEpsilon;
  std::size_t high = rounded.size() - 1;
  while (high > 0 && std::fabs(static_cast<double>(rounded[high])) < eps / 16 * biggest) --high;
  std::size_t low = 0;
  while (low < high && rounded[low] == S(0)) ++low;
  p.low = static_cast<std::uint8_t>(low);
  p.high = static_cast<std::uint8_t>(high);
  p.coeffs.assign(rounded.begin() + static_cast<std::ptrdiff_t>(low),
                  rounded.begin() + static_cast<std::ptrdiff_t>(high) + 1);
  return p;
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
  while (term > ScalarTraits<S>::kEpsilon / 4 && degree < 30) {
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
  struct Slot {
    std::vector<S> grid;
    Polynomial<S> poly;
  };
  std::vector<Slot> slots;
  bool in_transition = true;
  for (const Candidate& c : cands) {
    if (c.kind == Candidate::Kind::kQd && in_transition) {
      t.transition_slots = static_cast<std::uint8_t>(slots.size());
      in_transition = false;
    }
    Slot s;
    for (double v : c.grid) s.grid.push_back(static_cast<S>(v));
    s.poly = trimmed<S>(c.coeffs);
    std::size_t index = 0;
    while (index < slots.size() && !(slots[index].grid == s.grid && slots[index].poly == s.poly)) ++index;
    if (index == slots.size()) slots.push_back(s);
    if (slots.size() > 127) throw DesignError("table: more than 127 free entries");
    const auto code = static_cast<std::int8_t>(index);
    if (c.kind == Candidate::Kind::kPhi) t.phi_slot[c.i * N + c.j] = code;
    if (c.kind == Candidate::Kind::kGamma) t.gamma_slot[c.i * M + c.j] = code;
    if (c.kind == Candidate::Kind::kQd) t.qd_slot[c.i * N + c.j] = t.qd_slot[c.j * N + c.i] = code;
  }
  if (in_transition) t.transition_slots = static_cast<std::uint8_t>(slots.size());
  t.slots = static_cast<std::uint8_t>(slots.size());
  for (const Slot& s : slots) {
    t.residual_low.push_back(s.poly.low);
    t.residual_high.push_back(s.poly.high);
    t.residual_offset.push_back(static_cast<std::uint8_t>(t.residual_coefficients.size()));
    t.residual_coefficients.insert(t.residual_coefficients.end(), s.poly.coeffs.begin(), s.poly.coeffs.end());
  }
  if (t.residual_coefficients.size() > 255) throw DesignError("table: more than 255 residual coefficients");

  // Layout: fewest levels that fit table.max_bytes, then fewest bytes.
  const std::size_t fixed_bytes = sizeof(S) * t.residual_coefficients.size() + 2 * N * N + N * M + 3U * t.slots;
  const auto cost = [&](std::size_t entries, std::size_t levels) {
    return fixed_bytes + sizeof(S) * entries * t.slots + 4 * levels;
  };
  // table.max_bytes budgets 4-byte storage (the float firmware table); wider formats scale.
  const std::size_t budget = static_cast<std::size_t>(plant.table_max_bytes) * std::max<std::size_t>(1, sizeof(S) / 4);
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
    throw DesignError("table.max_bytes: " + std::to_string(budget) + " bytes of " + std::to_string(sizeof(S)) +
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
      std::vector<S> entry(t.slots);
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
    lut.discretize(tau, got, WithQd::kYes);
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
template TableData<double> build_table<double>(const PlantDescription&, const DesignResult&, const PlantPatterns&);
template TableAccuracy measure_accuracy<float>(const TableData<float>&, const PlantDescription&, const DesignResult&);
template TableAccuracy measure_accuracy<double>(const TableData<double>&, const PlantDescription&, const DesignResult&);

}  // namespace oneshot::design
