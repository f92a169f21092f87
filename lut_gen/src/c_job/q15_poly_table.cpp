/// @file q15_poly_table.cpp
/// @brief The q15 per-interval polynomial table (see q15_poly_table.hpp).
#include "c_job/q15_poly_table.hpp"

#include <algorithm>
#include <cmath>

#include "oneshot/design/dimension_dispatch.hpp"
#include "oneshot/design/fixed_size.hpp"
#include "oneshot/generic_discretizer.hpp"

namespace oneshot::design::cjob {

namespace {

constexpr int kMaxDegree = 6;
constexpr int kFitPoints = 33;    // least-squares samples per interval
constexpr int kCheckPoints = 97;  // error check per interval

template <std::size_t N, std::size_t M>
std::vector<std::vector<double>> exact_of(const PlantDescription& plant, const DesignResult& d,
                                          const std::vector<Q15Member>& members, const std::vector<double>& t_us) {
  const GenericDiscretizer<UniformFormat<double>, N, M> gen(continuous_model_per_us<double, N, M>(plant, d));
  std::vector<std::vector<double>> out;
  for (double t : t_us) {
    Discretization<UniformFormat<double>, N, M> dd;
    if (gen.discretize(static_cast<std::int32_t>(t), dd, WithQd::kYes) != Status::kOk) {
      throw DesignError("C job: the exponential of A·t fails at t = " + std::to_string(t) + " us");
    }
    std::vector<double> row;
    for (const Q15Member& m : members)
      row.push_back(m.member == "phi" ? dd.phi(m.i, m.j) : m.member == "gamma" ? dd.gamma(m.i, m.j) : dd.qd(m.i, m.j));
    out.push_back(row);
  }
  return out;
}

/// Least-squares c_1 … c_D of y(r) − c_0 on the basis r, …, r^D (D ≤ 6); c_0 first.
std::vector<double> fit(const std::vector<double>& r, const std::vector<double>& y, double c0, int degree) {
  std::vector<double> c{c0};
  if (degree == 0) return c;
  std::vector<int> exps;
  for (int e = 1; e <= degree; ++e) exps.push_back(e);
  std::vector<double> y0;
  for (double v : y) y0.push_back(v - c0);
  const std::vector<double> a = least_squares(r, y0, exps);
  c.insert(c.end(), a.begin(), a.end());
  return c;
}

double horner(const std::vector<double>& c, double r) {
  double v = 0;
  for (std::size_t k = c.size(); k-- > 0;) v = v * r + c[k];
  return v;
}

}  // namespace

std::vector<double> least_squares(const std::vector<double>& s, const std::vector<double>& y,
                                  const std::vector<int>& exps) {
  const std::size_t n = exps.size();
  std::vector<std::vector<double>> a(n, std::vector<double>(n + 1, 0.0));
  for (std::size_t k = 0; k < s.size(); ++k) {
    std::vector<double> b(n);
    for (std::size_t p = 0; p < n; ++p) b[p] = std::pow(s[k], exps[p]);
    for (std::size_t p = 0; p < n; ++p) {
      for (std::size_t q = 0; q < n; ++q) a[p][q] += b[p] * b[q];
      a[p][n] += b[p] * y[k];
    }
  }
  for (std::size_t p = 0; p < n; ++p) {  // Gauss-Jordan with partial pivoting
    std::size_t best = p;
    for (std::size_t q = p + 1; q < n; ++q)
      if (std::fabs(a[q][p]) > std::fabs(a[best][p])) best = q;
    std::swap(a[p], a[best]);
    if (a[p][p] == 0.0) continue;
    for (std::size_t q = 0; q < n; ++q) {
      if (q == p) continue;
      const double f = a[q][p] / a[p][p];
      for (std::size_t k = p; k <= n; ++k) a[q][k] -= f * a[p][k];
    }
  }
  std::vector<double> c(n, 0.0);
  for (std::size_t p = 0; p < n; ++p) c[p] = a[p][p] == 0.0 ? 0.0 : a[p][n] / a[p][p];
  return c;
}

std::vector<std::vector<double>> exact_member_values(const PlantDescription& plant, const DesignResult& design,
                                                     const std::vector<Q15Member>& members,
                                                     const std::vector<double>& t_us) {
  return with_dimensions(plant.n(), plant.m(), 1, [&](auto n, auto m, auto) {
    return exact_of<decltype(n)::value, decltype(m)::value>(plant, design, members, t_us);
  });
}

std::vector<std::vector<std::size_t>> shared_member_groups(std::size_t count,
                                                           const std::function<bool(std::size_t, std::size_t)>& same) {
  std::vector<std::vector<std::size_t>> groups;
  std::vector<bool> grouped(count, false);
  for (std::size_t a = 0; a < count; ++a) {
    if (grouped[a]) continue;
    std::vector<std::size_t> g{a};
    for (std::size_t b = a + 1; b < count; ++b) {
      if (!grouped[b] && same(a, b)) {
        g.push_back(b);
        grouped[b] = true;
      }
    }
    groups.push_back(std::move(g));
  }
  return groups;
}

Q15PolyTable design_q15_poly_table(const PlantDescription& plant, const DesignResult& design, const Arith& ar,
                                   std::int32_t g_us, std::int32_t range_us, std::vector<Q15Member> members,
                                   bool nearest) {
  Q15PolyTable t;
  t.members = std::move(members);
  const auto intervals = static_cast<std::size_t>(range_us / g_us) + 1;
  if (intervals > 255) throw DesignError("C job q15: more than 255 grid intervals (raise the table granularity)");
  // Exact values on every interval's fit and check points (and its left end).
  std::vector<double> fit_r, check_r, times;
  for (int s = 0; s < kFitPoints; ++s) fit_r.push_back(static_cast<double>(s) / kFitPoints);
  for (int s = 0; s < kCheckPoints; ++s) check_r.push_back((static_cast<double>(s) + 0.5) / kCheckPoints);
  for (std::size_t k = 0; k < intervals; ++k) {
    for (double r : fit_r) times.push_back(static_cast<double>(k) * g_us + r * g_us);
    for (double r : check_r) times.push_back(static_cast<double>(k) * g_us + r * g_us);
  }
  // Time in µs must be an integer for the discretizer: round the sample points, keep their r.
  for (double& x : times) x = std::round(x);
  const auto values = exact_member_values(plant, design, t.members, times);
  const std::size_t per = static_cast<std::size_t>(kFitPoints + kCheckPoints);
  const auto r_of = [&](std::size_t k, std::size_t s) { return (times[k * per + s] - static_cast<double>(k) * g_us) / g_us; };
  // Slots: members with the same values (at every sample) and format share one polynomial.
  const auto groups = shared_member_groups(t.members.size(), [&](std::size_t a, std::size_t b) {
    if (ar.fmt(t.members[b].q).frac != ar.fmt(t.members[a].q).frac) return false;
    for (const auto& row : values)
      if (row[a] != row[b]) return false;
    return true;
  });
  for (const auto& g : groups) {
    Q15Slot slot;
    slot.members = g;
    t.slots.push_back(slot);
  }
  // Per slot: the lowest degree that fits every interval within 1/4 LSB, then the block exponent.
  std::vector<std::vector<std::vector<double>>> coeff(t.slots.size());  // [slot][k][j]
  for (std::size_t si = 0; si < t.slots.size(); ++si) {
    Q15Slot& slot = t.slots[si];
    const std::size_t a = slot.members[0];
    const QFormat dest = ar.fmt(t.members[a].q);
    const double lsb = dest.resolution();
    for (int degree = 0; degree <= (nearest ? 0 : kMaxDegree); ++degree) {
      double worst = 0;
      std::vector<std::vector<double>> c(intervals);
      for (std::size_t k = 0; k < intervals; ++k) {
        std::vector<double> r, y;
        for (std::size_t s = 0; s < static_cast<std::size_t>(kFitPoints); ++s) {
          r.push_back(r_of(k, s));
          y.push_back(values[k * per + s][a]);
        }
        c[k] = fit(r, y, values[k * per][a], degree);
        if (k + 1 < intervals && !nearest)
          for (std::size_t s = static_cast<std::size_t>(kFitPoints); s < per; ++s)
            worst = std::max(worst, std::fabs(horner(c[k], r_of(k, s)) - values[k * per + s][a]) / lsb);
      }
      slot.degree = degree;
      slot.max_error_lsb = worst;
      coeff[si] = c;
      if (worst <= 0.25) break;
    }
    if (slot.max_error_lsb > 0.25) {
      throw DesignError("C job q15: Phi/Gamma/Q_d entry needs a polynomial of degree > " + std::to_string(kMaxDegree) +
                        " per " + std::to_string(g_us) + " us interval (lower the table granularity)");
    }
    double sum = 0;
    for (const auto& c : coeff[si]) {
      double s = 0;
      for (double v : c) s += std::fabs(v);
      sum = std::max(sum, s);
    }
    const double budget = 32767.0 - 2.0 * (slot.degree + 2);  // Horner's rounding adds ≤ 1 per step
    int frac = slot.degree == 0 ? dest.frac : dest.frac + 8;  // guard bits for Horner only
    while (frac > -40 && std::ldexp(sum, frac) > budget) --frac;
    slot.frac = frac;
    slot.offset = t.width;
    t.width += static_cast<std::size_t>(slot.degree) + 1;
  }
  t.rows.assign(intervals, std::vector<long long>(t.width, 0));
  for (std::size_t si = 0; si < t.slots.size(); ++si)
    for (std::size_t k = 0; k < intervals; ++k)
      for (std::size_t j = 0; j < coeff[si][k].size(); ++j)
        t.rows[k][t.slots[si].offset + j] = std::llround(std::ldexp(coeff[si][k][j], t.slots[si].frac));
  return t;
}

}  // namespace oneshot::design::cjob
