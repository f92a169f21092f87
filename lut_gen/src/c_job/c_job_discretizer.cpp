/// @file c_job_discretizer.cpp
/// @brief The generated job's table discretizer: TableDiscretizer::discretize unrolled over
///        the plant's free entries, with constant residual polynomials and exact
///        reciprocal multiplications for the grid index.
#include <stdexcept>

#include "c_job/c_job_variant.hpp"
#include "c_job/q15_poly_table.hpp"
#include "oneshot/table_view.hpp"

namespace oneshot::design::cjob {

VariantEmitter::VariantEmitter(const PlantDescription& plant, const DesignResult& design,
                               const PlantPatterns& patterns, const VariantSpec& spec)
    : plant_(plant), design_(design), pat_(patterns), spec_(spec), n_(plant.n()), m_(plant.m()), p_(plant.p()) {
  if (p_ != 1) throw DesignError("C job: the generated job supports one measured output (p = 1)");
  if (design_.actuator_steps > 65535) throw DesignError("C job: PWM codes are uint16_t, board.pwm_duty_steps must be <= 65535");
  if (plant_.board.adc_bits > 16) throw DesignError("C job: ADC codes are uint16_t, board.adc_bits must be <= 16");
  for (std::size_t i = 0; i < n_; ++i) {
    for (std::size_t j = 0; j < n_; ++j)
      if (pat_.phi.is_free(i, j)) phi_free_.emplace_back(i, j);
    for (std::size_t j = 0; j < m_; ++j) {
      if (pat_.gamma.is_one(i, j)) throw DesignError("C job: Gamma has a structural one");
      if (pat_.gamma.is_free(i, j)) gamma_free_.emplace_back(i, j);
    }
    for (std::size_t j = i; j < n_; ++j) {
      if (pat_.qd.is_one(i, j)) throw DesignError("C job: Q_d has a structural one");
      if (pat_.qd.is_free(i, j)) qd_free_.emplace_back(i, j);
    }
  }
  if (!spec_.exact_subgrid && plant_.period_us % spec_.table.granularity_us != 0) {
    throw DesignError("C job: the nearest-grid-point variant needs the period (" + std::to_string(plant_.period_us) +
                      " us) to be a multiple of the table granularity (" +
                      std::to_string(spec_.table.granularity_us) + " us)");
  }
}

std::vector<Q15Member> VariantEmitter::free_members() const {
  std::vector<Q15Member> members;
  const auto add = [&](const char* name, const std::vector<std::pair<std::size_t, std::size_t>>& free, Qty q) {
    for (std::size_t k = 0; k < free.size(); ++k) members.push_back({name, k, free[k].first, free[k].second, q});
  };
  add("phi", phi_free_, Qty::kTransition);
  add("gamma", gamma_free_, Qty::kInputGain);
  add("qd", qd_free_, Qty::kCovariance);
  return members;
}

std::int32_t VariantEmitter::tau_bound_us() const {
  // Beyond (kMaxExtensions + 1)·range + h + g every path clamps: see emit_run().
  return 4 * spec_.table.range_us + plant_.period_us + spec_.table.granularity_us;
}

std::size_t VariantEmitter::upper_index(std::size_t n, std::size_t i, std::size_t j) {
  if (i > j) std::swap(i, j);
  return i * n - (i * (i + 1)) / 2 + j;
}

namespace {
std::size_t index_of(const std::vector<std::pair<std::size_t, std::size_t>>& v, std::size_t i, std::size_t j) {
  for (std::size_t k = 0; k < v.size(); ++k)
    if (v[k].first == i && v[k].second == j) return k;
  throw std::logic_error("C job: entry is not free");
}
}  // namespace

Val VariantEmitter::phi(const std::string& p, std::size_t i, std::size_t j) const {
  if (pat_.phi.is_zero(i, j)) return Val::zero();
  if (pat_.phi.is_one(i, j)) return Val::one();
  return ar().val(Qty::kTransition, p + "->phi[" + std::to_string(index_of(phi_free_, i, j)) + "]");
}

Val VariantEmitter::gamma(const std::string& p, std::size_t i, std::size_t j) const {
  if (pat_.gamma.is_zero(i, j)) return Val::zero();
  return ar().val(Qty::kInputGain, p + "->gamma[" + std::to_string(index_of(gamma_free_, i, j)) + "]");
}

Val VariantEmitter::qd(const std::string& p, std::size_t i, std::size_t j) const {
  if (i > j) std::swap(i, j);
  if (pat_.qd.is_zero(i, j)) return Val::zero();
  return ar().val(Qty::kCovariance, p + "->qd[" + std::to_string(index_of(qd_free_, i, j)) + "]");
}

void VariantEmitter::emit_table(CodeWriter& w) const {
  const TableText& t = spec_.table;
  if (grid()) {
    emit_grid(w);
    return;
  }
  std::string times;
  std::uint32_t spacing = 1;
  for (std::size_t l = 0; l < t.radix.size(); ++l) {
    times += (l ? ", " : "") + std::string("level ") + std::to_string(l) + ": k x " +
             std::to_string(spacing * static_cast<std::uint32_t>(t.granularity_us)) + " us";
    spacing *= t.radix[l];
  }
  w.line("/* The table: " + std::to_string(t.entries) + " entries x " + std::to_string(t.slots) +
         " free values (" + times + "). */");
  w.open("static ONESHOT_CONST_TABLE const " + t.value_ctype + " " + fn("values") + "[" + std::to_string(t.entries) +
         "][" + std::to_string(t.slots) + "] = {");
  for (std::size_t e = 0; e < t.entries; ++e) {
    std::string row = "{";
    for (std::size_t s = 0; s < t.slots; ++s) row += (s ? ", " : "") + t.values[e * t.slots + s];
    w.line(row + (e + 1 < t.entries ? "}," : "}"));
  }
  w.close("};");
}

void VariantEmitter::emit_grid(CodeWriter& w) const {
  const TableText& t = spec_.table;
  const std::size_t points = t.grid_values.size() / t.slots;
  w.line("/* The grid table: Phi, Gamma, Q_d at every grid point k x " + std::to_string(t.granularity_us) +
         " us, k = 0.." + std::to_string(points - 1) + ", " + std::to_string(t.slots) + " free values each,");
  w.line("   composed at generation time in float exactly as the " + std::to_string(t.entries) +
         " stored mixed-radix entries compose (TableDiscretizer::in_range). */");
  w.open("static ONESHOT_CONST_TABLE const float " + fn("grid") + "[" + std::to_string(points) + "][" +
         std::to_string(t.slots) + "] = {");
  for (std::size_t e = 0; e < points; ++e) {
    std::string row = "{";
    for (std::size_t s = 0; s < t.slots; ++s) row += (s ? ", " : "") + t.grid_values[e * t.slots + s];
    w.line(row + (e + 1 < points ? "}," : "}"));
  }
  w.close("};");
}

void VariantEmitter::emit_triple(CodeWriter& w) const {
  w.line("/* Phi, Gamma, Q_d over one interval: only the entries that are not structurally 0 or 1. */");
  w.open("typedef struct {");
  const auto member = [&](Qty q, const char* name, const std::vector<std::pair<std::size_t, std::size_t>>& v) {
    if (v.empty()) return;
    std::string list;
    for (const auto& [i, j] : v) list += (list.empty() ? "" : ", ") + std::string("(") + std::to_string(i) + "," + std::to_string(j) + ")";
    w.line(ar().scratch_ctype(q) + " " + name + "[" + std::to_string(v.size()) + "];  /* " + list + " */");
  };
  member(Qty::kTransition, "phi", phi_free_);
  member(Qty::kInputGain, "gamma", gamma_free_);
  member(Qty::kCovariance, "qd", qd_free_);
  if (phi_free_.empty() && gamma_free_.empty() && qd_free_.empty()) w.line("uint8_t unused;");
  w.close("} " + triple_type() + ";");
}

void VariantEmitter::emit_pick(CodeWriter& w, const std::string& dest, Qty q, std::int16_t slot,
                               const std::string& raw_prefix, bool residual) const {
  if (slot == kSlotZero) {
    w.line(dest + " = " + ar().zero(q) + ";");
  } else if (slot == kSlotOne) {
    bool sat = false;
    const std::string one = ar().one(q, sat);
    if (sat) w.line("*sat = 1u;  /* one() does not fit this format */");
    w.line(dest + " = " + one + ";");
  } else {
    const auto s = static_cast<std::size_t>(slot);
    const int frac = fixed() ? (residual ? spec_.table.residual_frac[s] : spec_.table.value_frac[s]) : 0;
    w.line(dest + " = " + ar().slot_to(q, raw_prefix + std::to_string(s) + (residual ? "" : "]"), frac, residual ? 32 : 16) + ";");
  }
}

void VariantEmitter::emit_load(CodeWriter& w) const {
  const TableText& t = spec_.table;
  const std::string raw = fn(grid() ? "grid" : "values") + "[entry][";
  const bool wide = grid() && t.grid_values.size() / t.slots > 256;
  w.line(grid() ? "/* d = grid point `entry` of the grid table. */"
                : "/* d = stored entry `entry` (TableDiscretizer::load_entry). */");
  w.open("static void " + fn("load") + "(" + (wide ? "uint16_t" : "uint8_t") + " entry, " + triple_type() + " *d" +
         sat_param() + ") {");
  if (fixed()) w.line("(void)sat;");
  for (std::size_t k = 0; k < phi_free_.size(); ++k) {
    const auto [i, j] = phi_free_[k];
    emit_pick(w, "d->phi[" + std::to_string(k) + "]", Qty::kTransition, t.phi_slot[i * n_ + j], raw, false);
  }
  for (std::size_t k = 0; k < gamma_free_.size(); ++k) {
    const auto [i, j] = gamma_free_[k];
    emit_pick(w, "d->gamma[" + std::to_string(k) + "]", Qty::kInputGain, t.gamma_slot[i * m_ + j], raw, false);
  }
  for (std::size_t k = 0; k < qd_free_.size(); ++k) {
    const auto [i, j] = qd_free_[k];
    emit_pick(w, "d->qd[" + std::to_string(k) + "]", Qty::kCovariance, t.qd_slot[i * n_ + j], raw, false);
  }
  w.close();
}

void VariantEmitter::emit_residual(CodeWriter& w) const {
  const TableText& t = spec_.table;
  const std::int32_t g = t.granularity_us;
  w.line("/* d over delta = residual_us < g from each slot's Taylor polynomial in r = delta/g, Horner");
  w.line("   (TableDiscretizer::residual). */");
  w.open("static void " + fn("residual") + "(int32_t residual_us, " + triple_type() + " *d" + sat_param() + ") {");
  if (fixed()) {
    const int f = ar().fmt(Qty::kFraction).frac;
    if (f < 0 || f + 16 > 31) throw DesignError("C job: the sub-grid fraction needs 0..15 fractional bits");
    const std::uint64_t scale = ((std::uint64_t{1} << (f + 16)) + static_cast<std::uint64_t>(g) / 2) /
                                static_cast<std::uint64_t>(g);  // ScalarTraits<F>::fraction_scale
    w.line("/* r = delta/g: one 32-bit multiply by the precomputed 2^" + std::to_string(f + 16) + "/g. */");
    w.line("const int16_t r = os_sat16((int32_t)(((uint32_t)residual_us * " + u32_literal(scale) +
           " + UINT32_C(0x8000)) >> 16), sat);");
    const std::string half = int_literal(std::int64_t{1} << (f - 1), 64);
    for (std::size_t s = 0; s < t.slots; ++s) {
      const auto& c = t.coeff_raw[s];
      const std::string v = "v" + std::to_string(s);
      w.line("int32_t " + v + " = " + int_literal(c.back(), 32) + ";");
      for (std::size_t k = c.size() - 1; k > 0; --k)
        w.line(v + " = os_sat32(((os_m32x16(" + v + ", r) + " + half + ") >> " + std::to_string(f) + ") + " +
               int_literal(c[k - 1], 64) + ", sat);");
      for (std::uint8_t k = 0; k < t.low[s]; ++k)
        w.line(v + " = os_sat32((os_m32x16(" + v + ", r) + " + half + ") >> " + std::to_string(f) + ", sat);");
    }
  } else {
    const float scale = 1.0F / static_cast<float>(g);  // ScalarTraits<float>::fraction_scale
    if (g <= 65536) {  // 0 < residual_us < g: an exact integer conversion
      w.line("const float r = os_fmul(os_f32_of_u16((uint32_t)residual_us), " + float_literal(scale) + ");");
    } else {
      w.line("const float r = os_fmul((float)residual_us, " + float_literal(scale) + ");");
    }
    for (std::size_t s = 0; s < t.slots; ++s) {
      const auto& c = t.coeff_float[s];
      const std::string v = "v" + std::to_string(s);
      w.line("float " + v + " = " + float_literal(c.back()) + ";");
      for (std::size_t k = c.size() - 1; k > 0; --k) {
        w.line(v + " = os_fmul(" + v + ", r);");
        // v + 0 only turns -0 into +0, which a later v·r + c (c != 0) makes irrelevant: skip it then.
        bool later = false;
        for (std::size_t j = 0; j + 1 < k; ++j) later = later || c[j] != 0.0F;
        if (c[k - 1] == 0.0F && later) continue;
        w.line(v + " = " + v + " + " + float_literal(c[k - 1]) + ";");
      }
      for (std::uint8_t k = 0; k < t.low[s]; ++k) w.line(v + " = os_fmul(" + v + ", r);");
    }
  }
  for (std::size_t k = 0; k < phi_free_.size(); ++k) {
    const auto [i, j] = phi_free_[k];
    emit_pick(w, "d->phi[" + std::to_string(k) + "]", Qty::kTransition, t.phi_slot[i * n_ + j], "v", true);
  }
  for (std::size_t k = 0; k < gamma_free_.size(); ++k) {
    const auto [i, j] = gamma_free_[k];
    emit_pick(w, "d->gamma[" + std::to_string(k) + "]", Qty::kInputGain, t.gamma_slot[i * m_ + j], "v", true);
  }
  for (std::size_t k = 0; k < qd_free_.size(); ++k) {
    const auto [i, j] = qd_free_[k];
    emit_pick(w, "d->qd[" + std::to_string(k) + "]", Qty::kCovariance, t.qd_slot[i * n_ + j], "v", true);
  }
  w.close();
}

void VariantEmitter::emit_identity(CodeWriter& w) const {
  w.line("/* The zero-length interval: Phi = I, Gamma = 0, Q_d = 0 (Discretization::identity). */");
  w.open("static void " + fn("identity") + "(" + triple_type() + " *d" + sat_param() + ") {");
  if (fixed()) w.line("(void)sat;");
  for (std::size_t k = 0; k < phi_free_.size(); ++k) {
    const auto [i, j] = phi_free_[k];
    if (i == j) {
      bool sat = false;
      const std::string one = ar().one(Qty::kTransition, sat);
      if (sat) w.line("*sat = 1u;  /* one() does not fit this format */");
      w.line("d->phi[" + std::to_string(k) + "] = " + one + ";");
    } else {
      w.line("d->phi[" + std::to_string(k) + "] = " + ar().zero(Qty::kTransition) + ";");
    }
  }
  for (std::size_t k = 0; k < gamma_free_.size(); ++k)
    w.line("d->gamma[" + std::to_string(k) + "] = " + ar().zero(Qty::kInputGain) + ";");
  for (std::size_t k = 0; k < qd_free_.size(); ++k)
    w.line("d->qd[" + std::to_string(k) + "] = " + ar().zero(Qty::kCovariance) + ";");
  w.close();
}

void VariantEmitter::emit_congruence(CodeWriter& w, const std::string& a, const std::vector<std::vector<Val>>& p,
                                     const std::string& q, const std::string& out) const {
  // congruence_add: T = A·P (P read through its upper triangle), out_ij = Σ_k T_ik A_jk + Q_ij, j ≥ i.
  const std::string cov = ar().ctype(Qty::kCovariance);
  const auto used = [&](std::size_t i, std::size_t k) {
    for (std::size_t j = i; j < n_; ++j)
      if (!pat_.phi.is_zero(j, k)) return true;
    return false;
  };
  const auto t_name = [&](std::size_t i, std::size_t k) { return out + "t" + std::to_string(i) + std::to_string(k); };
  for (std::size_t i = 0; i < n_; ++i)
    for (std::size_t j = 0; j < n_; ++j) {
      if (!used(i, j)) continue;
      std::vector<Term> terms;
      for (std::size_t k = 0; k < n_; ++k) add_term(terms, false, phi(a, i, k), p[k < j ? k : j][k < j ? j : k]);
      ar().accumulate(w, "const " + cov + " " + t_name(i, j), Qty::kCovariance, terms);
    }
  for (std::size_t i = 0; i < n_; ++i)
    for (std::size_t j = i; j < n_; ++j) {
      std::vector<Term> terms;
      for (std::size_t k = 0; k < n_; ++k) {
        if (pat_.phi.is_zero(j, k)) continue;
        add_term(terms, false, ar().val(Qty::kCovariance, t_name(i, k)), phi(a, j, k));
      }
      if (!q.empty()) add_value(terms, false, qd(q, i, j));
      ar().accumulate(w, "const " + cov + " " + out + std::to_string(i) + std::to_string(j), Qty::kCovariance, terms);
    }
}

void VariantEmitter::emit_compose(CodeWriter& w) const {
  w.line("/* d <- d followed by e (compose_into): Phi(a+b) = Phi(b) Phi(a),");
  w.line("   Gamma(a+b) = Phi(b) Gamma(a) + Gamma(b), Q_d(a+b) = Phi(b) Q_d(a) Phi(b)^T + Q_d(b). */");
  w.open("static void " + fn("compose") + "(" + triple_type() + " *d, const " + triple_type() + " *e" + sat_param() +
         ") {");
  if (fixed()) w.line("(void)sat;");
  for (const auto& [i, j] : gamma_free_) {
    std::vector<Term> terms;
    for (std::size_t k = 0; k < n_; ++k) add_term(terms, false, phi("e", i, k), gamma("d", k, j));
    add_value(terms, false, gamma("e", i, j));
    ar().accumulate(w, "const " + ar().ctype(Qty::kInputGain) + " g" + std::to_string(i) + std::to_string(j),
                    Qty::kInputGain, terms);
  }
  std::vector<std::vector<Val>> dq(n_, std::vector<Val>(n_));
  for (std::size_t i = 0; i < n_; ++i)
    for (std::size_t j = 0; j < n_; ++j) dq[i][j] = qd("d", i, j);
  if (!qd_free_.empty()) emit_congruence(w, "e", dq, "e", "q");
  for (const auto& [i, j] : phi_free_) {
    std::vector<Term> terms;
    for (std::size_t k = 0; k < n_; ++k) add_term(terms, false, phi("e", i, k), phi("d", k, j));
    ar().accumulate(w, "const " + ar().ctype(Qty::kTransition) + " f" + std::to_string(i) + std::to_string(j),
                    Qty::kTransition, terms);
  }
  for (std::size_t k = 0; k < gamma_free_.size(); ++k)
    w.line("d->gamma[" + std::to_string(k) + "] = g" + std::to_string(gamma_free_[k].first) +
           std::to_string(gamma_free_[k].second) + ";");
  for (std::size_t k = 0; k < qd_free_.size(); ++k)
    w.line("d->qd[" + std::to_string(k) + "] = q" + std::to_string(qd_free_[k].first) +
           std::to_string(qd_free_[k].second) + ";");
  for (std::size_t k = 0; k < phi_free_.size(); ++k)
    w.line("d->phi[" + std::to_string(k) + "] = f" + std::to_string(phi_free_[k].first) +
           std::to_string(phi_free_[k].second) + ";");
  w.close();
}

void VariantEmitter::emit_in_range(CodeWriter& w) {
  const TableText& t = spec_.table;
  const std::int32_t g = t.granularity_us;
  const auto max_index = static_cast<std::uint32_t>(t.range_us / g);
  if (grid()) {
    const bool wide = t.grid_values.size() / t.slots > 256;
    w.line("/* d over 0 <= tau_us <= range, tau_us a multiple of g (the job rounds tau to the grid first):");
    w.line("   one grid point (TableDiscretizer::in_range, its compositions done at generation time). */");
    w.open("static void " + fn("in_range") + "(int32_t tau_us, " + triple_type() + " *d" + sat_param() + ") {");
    w.line(fn("load") + "((" + (wide ? "uint16_t" : "uint8_t") + ")" +
           divide_by_constant("tau_us", static_cast<std::uint32_t>(g), static_cast<std::uint32_t>(t.range_us), divisions_) +
           ", d" + sat_arg() + ");");
    w.close();
    return;
  }
  w.line("/* d over 0 <= tau_us <= range (TableDiscretizer::in_range): the residual, then one stored");
  w.line("   entry per non-zero mixed-radix digit of tau/g, finest level first. */");
  w.open("static void " + fn("in_range") + "(int32_t tau_us, " + triple_type() + " *d" + sat_param() + ") {");
  w.line("int32_t index = " + divide_by_constant("tau_us", static_cast<std::uint32_t>(g),
                                                 static_cast<std::uint32_t>(t.range_us), divisions_) + ";");
  w.line(triple_type() + " e;");
  w.line("uint8_t have = 0u;");
  bool divides = false;
  for (std::uint32_t l = 0, top = max_index; l < t.radix.size(); top /= t.radix[l], ++l) divides = divides || top >= t.radix[l];
  if (divides) w.line("int32_t next;");
  w.line("int32_t digit;");
  if (spec_.exact_subgrid) {
    w.line("const int32_t residual_us = tau_us - index * " + int_literal(g, 32) + ";");
    w.open("if (residual_us > 0) {").line(fn("residual") + "(residual_us, d" + sat_arg() + ");").line("have = 1u;").close();
  } else {
    w.line("/* tau_us is a multiple of g here (the job rounds tau to the grid first). */");
  }
  std::uint32_t level_max = max_index;
  for (std::size_t l = 0; l < t.radix.size(); ++l) {
    const std::uint32_t radix = t.radix[l];
    w.open("if (index > 0) {");
    if (level_max < radix) {
      w.line("digit = index;").line("index = 0;");
    } else {
      w.line("next = " + divide_by_constant("index", radix, level_max, divisions_) + ";");
      w.line("digit = index - next * " + int_literal(radix, 32) + ";").line("index = next;");
    }
    w.open("if (digit != 0) {");
    w.line("const uint8_t entry = (uint8_t)(" + std::to_string(t.level_offset[l]) + " + digit - 1);");
    w.open("if (have) {")
        .line(fn("load") + "(entry, &e" + sat_arg() + ");")
        .line(fn("compose") + "(d, &e" + sat_arg() + ");");
    w.middle("} else {").line(fn("load") + "(entry, d" + sat_arg() + ");").line("have = 1u;");
    w.close().close().close();
    level_max /= radix;
  }
  w.open("if (!have) {").line(fn("identity") + "(d" + sat_arg() + ");").close();
  w.close();
}

void VariantEmitter::emit_discretize(CodeWriter& w) {
  const TableText& t = spec_.table;
  const std::string range = int_literal(t.range_us, 32);
  const auto max_arg = static_cast<std::uint32_t>(plant_.period_us + tau_bound_us());
  w.line("/* Phi, Gamma, Q_d over tau_us (TableDiscretizer::discretize, OutOfRange::kExtend): tau < 0");
  w.line("   clamps to 0; range < tau <= 4 range composes the full range; beyond, clamps. */");
  w.open("static uint8_t " + fn("discretize") + "(int32_t tau_us, " + triple_type() + " *d" + sat_param() + ") {");
  w.line("uint8_t status = ONESHOT_JOB_STATUS_OK;");
  w.line("int32_t repeats, remainder, k;");
  w.line(triple_type() + " full;");
  w.open("if (tau_us < 0) {").line("tau_us = 0;").line("status = ONESHOT_JOB_STATUS_CLAMPED;").close();
  w.open("if (tau_us <= " + range + ") {").line(fn("in_range") + "(tau_us, d" + sat_arg() + ");").line("return status;").close();
  emit_range_split(w, "", static_cast<std::uint32_t>(t.range_us), max_arg, divisions_);
  w.line(fn("in_range") + "(" + range + ", &full" + sat_arg() + ");");
  w.open("if (remainder > 0) {").line(fn("in_range") + "(remainder, d" + sat_arg() + ");");
  w.middle("} else {").line("*d = full;").close();
  w.open("for (k = remainder > 0 ? 0 : 1; k < repeats; ++k) {").line(fn("compose") + "(d, &full" + sat_arg() + ");").close();
  w.line("return status;");
  w.close();
}

}  // namespace oneshot::design::cjob
