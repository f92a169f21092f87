/// @file float_poly.cpp
/// @brief The float_poly variant: design of its polynomials (see float_poly.hpp) and the
///        generated discretization (one evaluation per interval, no table, no composition).
#include "c_job/float_poly.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <set>

#include "c_job/c_job_variant.hpp"

namespace oneshot::design::cjob {

namespace {

constexpr int kMaxDegree = 6;
constexpr int kFitPoints = 257;
constexpr int kCheckPoints = 2001;

/// c0 + Σ c_e t^e in double, with the float coefficients the job uses.
double eval(float c0, const std::vector<int>& exps, const std::vector<float>& c, double t) {
  double v = static_cast<double>(c0);
  for (std::size_t k = 0; k < exps.size(); ++k) v += static_cast<double>(c[k]) * std::pow(t, exps[k]);
  return v;
}

struct Fit {
  bool ok = false;
  std::vector<float> coeff;
  double error = 0;
};

/// Fits y − c0 on exps over the fit points, rounds the coefficients to float (per µs^e) and
/// measures the error on the check points.
Fit fit_on(const std::vector<double>& fit_t, const std::vector<double>& fit_y, const std::vector<double>& check_t,
           const std::vector<double>& check_y, float c0, const std::vector<int>& exps, double domain) {
  Fit f;
  std::vector<double> s, y;
  for (std::size_t k = 0; k < fit_t.size(); ++k) {
    s.push_back(fit_t[k] / domain);
    y.push_back(fit_y[k] - static_cast<double>(c0));
  }
  const std::vector<double> a = least_squares(s, y, exps);
  for (std::size_t k = 0; k < exps.size(); ++k) {
    const double c = a[k] / std::pow(domain, exps[k]);
    const float cf = static_cast<float>(c);
    if (cf == 0.0F || !std::isnormal(cf) || std::fabs(c) < 0x1p-100 || std::fabs(c) > 0x1p100) return f;
    f.coeff.push_back(cf);
  }
  for (std::size_t k = 0; k < check_t.size(); ++k)
    f.error = std::max(f.error, std::fabs(eval(c0, exps, f.coeff, check_t[k]) - check_y[k]));
  f.ok = true;
  return f;
}

}  // namespace

std::optional<FloatPoly> design_float_poly(const PlantDescription& plant, const DesignResult& design,
                                           std::vector<Q15Member> members, std::int32_t domain_us) {
  FloatPoly p;
  p.members = std::move(members);
  p.domain_us = domain_us;
  const double domain = domain_us;
  std::vector<double> fit_t, check_t, times{0.0};
  for (int k = 0; k <= kFitPoints; ++k) fit_t.push_back(std::round(domain * k / kFitPoints));
  for (int k = 0; k <= kCheckPoints; ++k) check_t.push_back(std::round(domain * k / kCheckPoints));
  times.insert(times.end(), fit_t.begin(), fit_t.end());
  times.insert(times.end(), check_t.begin(), check_t.end());
  const auto values = exact_member_values(plant, design, p.members, times);
  const auto column = [&](std::size_t a, std::size_t from, std::size_t count) {
    std::vector<double> v;
    for (std::size_t k = from; k < from + count; ++k) v.push_back(values[k][a]);
    return v;
  };
  std::vector<double> max_value(p.members.size(), 0.0);
  for (const auto& row : values)
    for (std::size_t a = 0; a < row.size(); ++a) max_value[a] = std::max(max_value[a], std::fabs(row[a]));
  const auto groups = shared_member_groups(p.members.size(), [&](std::size_t a, std::size_t b) {
    for (const auto& row : values)
      if (!(std::fabs(row[a] - row[b]) <= 1e-12 * max_value[a])) return false;
    return true;
  });
  for (const auto& group : groups) {
    const std::size_t a = group.front();
    FloatPolySlot slot;
    slot.members = group;
    slot.max_value = max_value[a];
    const float c0 = static_cast<float>(values[0][a]);
    if (static_cast<double>(c0) != values[0][a]) return std::nullopt;  // v(0) is 0 or 1 (the identity)
    const auto ft = column(a, 1, fit_t.size());
    const auto ct = column(a, 1 + fit_t.size(), check_t.size());
    const double tol = kFloatPolyTolerance * slot.max_value;
    Fit best;
    std::vector<int> exps;
    for (int degree = 0; degree <= kMaxDegree && !best.ok; ++degree) {
      exps.clear();
      for (int e = 1; e <= degree; ++e) exps.push_back(e);
      Fit f = fit_on(fit_t, ft, check_t, ct, c0, exps, domain);
      if (f.ok && f.error <= tol) best = f;
    }
    if (!best.ok) return std::nullopt;
    for (std::size_t k = 0; k + 1 < exps.size();) {  // drop monomials the fit does without
      std::vector<int> fewer = exps;
      fewer.erase(fewer.begin() + static_cast<std::ptrdiff_t>(k));
      Fit f = fit_on(fit_t, ft, check_t, ct, c0, fewer, domain);
      if (f.ok && f.error <= tol) {
        exps = fewer;
        best = f;
      } else {
        ++k;
      }
    }
    slot.exps = exps;
    slot.coeff = best.coeff;
    slot.max_error = best.error;
    if (c0 != 0.0F) {
      slot.exps.insert(slot.exps.begin(), 0);
      slot.coeff.insert(slot.coeff.begin(), c0);
    }
    p.slots.push_back(slot);
  }
  return p;
}

bool VariantEmitter::available() {
  if (!spec_.polynomial) return true;
  auto p = design_float_poly(plant_, design_, free_members(), 4 * spec_.table.range_us);
  if (!p) return false;
  float_poly_ = std::make_shared<FloatPoly>(std::move(*p));
  return true;
}

void VariantEmitter::emit_float_poly(CodeWriter& w) const {
  const FloatPoly& p = *float_poly_;
  const std::string range = int_literal(spec_.table.range_us, 32);
  const std::string domain = int_literal(p.domain_us, 32);
  // Horner over each slot's powers: between two kept powers one multiply by t^gap.
  std::set<int> gaps;
  for (const FloatPolySlot& s : p.slots)
    for (std::size_t k = s.exps.size(); k-- > 0;) gaps.insert(s.exps[k] - (k > 0 ? s.exps[k - 1] : 0));
  gaps.erase(0);
  const int top_gap = gaps.empty() ? 1 : *gaps.rbegin();
  w.line("/* Phi, Gamma, Q_d over tau_us as one polynomial per free entry in t = tau_us, fitted to the exact");
  w.line("   discretization over 0.." + std::to_string(p.domain_us) + " us (max |error| <= 2^-21 max |entry|; the terms kept):");
  for (const FloatPolySlot& s : p.slots) {
    std::string names, terms;
    for (std::size_t m : s.members)
      names += (names.empty() ? "" : " = ") + p.members[m].member + "(" + std::to_string(p.members[m].i) + "," +
               std::to_string(p.members[m].j) + ")";
    for (int e : s.exps) terms += " t^" + std::to_string(e);
    char err[48];
    std::snprintf(err, sizeof err, "%.2g", s.max_value > 0 ? s.max_error / s.max_value : 0.0);
    w.line("     " + names + ":" + (terms.empty() ? " 0" : terms) + ", relative error " + err);
  }
  w.line("   tau < 0 clamps to 0; range < tau <= 4 range is extended; beyond, clamps (TableDiscretizer's");
  w.line("   statuses). Its own arithmetic: not the C++ core's table composition, not bit-identical to it. */");
  w.open("static uint8_t " + fn("discretize") + "(int32_t tau_us, " + triple_type() + " *d) {");
  w.line("uint8_t status = ONESHOT_JOB_STATUS_OK;");
  w.line("float t1;");
  w.open("if (tau_us < 0) {").line("tau_us = 0;").line("status = ONESHOT_JOB_STATUS_CLAMPED;");
  w.middle("} else if (tau_us > " + range + ") {").line("status = ONESHOT_JOB_STATUS_EXTENDED;");
  w.open("if (tau_us > " + domain + ") {").line("tau_us = " + domain + ";").line("status = ONESHOT_JOB_STATUS_CLAMPED;").close();
  w.close();
  if (p.domain_us <= 65535) {
    w.line("t1 = os_f32_of_u16((uint32_t)tau_us);");
  } else {
    w.line("/* (float)tau_us, exact (tau_us < 2^24), without a library conversion on the common path. */");
    w.open("if (tau_us <= INT32_C(65535)) {").line("t1 = os_f32_of_u16((uint32_t)tau_us);");
    w.middle("} else {")
        .line("t1 = os_fmul(os_f32_of_u16((uint32_t)tau_us >> 16), " + float_literal(65536.0F) +
              ") + os_f32_of_u16((uint32_t)tau_us & UINT32_C(0xFFFF));")
        .close();
  }
  w.open("{");
  for (int g = 2; g <= top_gap; ++g)
    if (gaps.count(g) != 0 || std::any_of(gaps.begin(), gaps.end(), [&](int x) { return x > g; }))
      w.line("const float t" + std::to_string(g) + " = os_fmul(t" + std::to_string(g - 1) + ", t1);");
  for (std::size_t si = 0; si < p.slots.size(); ++si) {
    const FloatPolySlot& s = p.slots[si];
    const std::string v = "v" + std::to_string(si);
    if (s.exps.empty()) {
      w.line("const float " + v + " = " + float_literal(0.0F) + ";");
    } else {
      std::size_t k = s.exps.size() - 1;
      w.line("float " + v + " = " + float_literal(s.coeff[k]) + ";");
      for (;; --k) {
        const int below = k > 0 ? s.exps[k - 1] : 0;
        if (s.exps[k] > below) w.line(v + " = os_fmul(" + v + ", t" + std::to_string(s.exps[k] - below) + ");");
        if (k == 0) break;
        w.line(v + " = " + v + " + " + float_literal(s.coeff[k - 1]) + ";");
      }
    }
    for (std::size_t m : s.members)
      w.line("d->" + p.members[m].member + "[" + std::to_string(p.members[m].index) + "] = " + v + ";");
  }
  w.close();
  w.line("return status;");
  w.close();
}

void VariantEmitter::emit_float_poly_law(CodeWriter& w) const {
  // u_j = N_u r - L (x - N_x r) with r = y_off + s_y sp, then steps = (u_j - u_min) steps_per_volt,
  // folded into one affine form of x and the set-point code: v = steps + 1/2
  //   = sum_i a_i x_i + b sp + c,  a_i = -L_ji spv,  b = (N_u + L N_x) s_y spv,
  //   c = ((N_u + L N_x) y_off - u_min) spv + 1/2,
  // and code = round half up (steps) clamped = (v <= 0) ? 0 : (v >= N) ? N : trunc(v).
  const std::int32_t steps = design_.actuator_steps;
  const std::string n = int_literal(steps, 32);
  for (std::size_t j = 0; j < m_; ++j) {
    const double spv = design_.steps_per_volt[j];
    if (!(spv > 0.0) || !std::isfinite(spv)) throw DesignError("C job float_poly: PWM steps per volt must be positive");
    double gain_r = design_.nu(j, 0);
    for (std::size_t i = 0; i < n_; ++i) gain_r += design_.l(j, i) * design_.nx(i, 0);
    std::vector<Term> terms;
    add_value(terms, false, ar().constant(Qty::kInput, (gain_r * design_.y_offset[0] - design_.u_min[j]) * spv + 0.5, "c"));
    for (std::size_t i = 0; i < n_; ++i) {
      const double a = -design_.l(j, i) * spv;
      if (a != 0.0) add_term(terms, false, state(i), ar().constant(Qty::kFeedbackGain, a, "a"));
    }
    const double b = gain_r * design_.volts_per_code[0] * spv;
    if (b != 0.0) add_term(terms, false, Val::code("setpoint_code"), ar().constant(Qty::kFeedbackGain, b, "b"));
    const std::string v = "v" + std::to_string(j);
    const std::string code = "code" + std::to_string(j);
    w.line("/* v = (u - u_min) steps_per_volt + 1/2, the law and the set-point's conversion folded into");
    w.line("   constants; code = clamp(trunc(v), 0, " + std::to_string(steps) + "): round half up. */");
    ar().accumulate(w, "const float " + v, Qty::kInput, terms);
    const float top = static_cast<float>(steps);
    w.open("if (!os_f32_positive(" + v + ")) {  /* !(0 < v) */").line(code + " = 0;");
    w.middle("} else if (!os_f32_below(" + v + ", " + u32_literal(float_bits(top)) + ", " + float_literal(top) + ")) {")
        .line(code + " = " + n + ";");
    w.middle("} else {").line(code + " = os_f32_trunc(" + v + ");  /* 0 < v < " + std::to_string(steps) + " */").close();
    emit_code_value(w, "s->u[" + std::to_string(j) + "]", Qty::kInput, "PWM", design_.u_min[j], design_.volts_per_step[j],
                    code);
  }
}

}  // namespace oneshot::design::cjob
