/// @file ncs_model.cpp
/// @brief Plant, design, approaches, scenarios and the S+ design of study `ncs`.
#include "ncs_model.hpp"

#include "ncs_cpu.hpp"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <optional>
#include <set>
#include <sstream>
#include <stdexcept>

#include "oneshot/design/dare.hpp"
#include "oneshot/design/dense_ops.hpp"
#include "oneshot/design/fixed_size.hpp"
#include "oneshot/engine/json_fields.hpp"

#ifndef ONESHOT_STUDY_PLANT_FILE
#error "ONESHOT_STUDY_PLANT_FILE must name lut_gen/plants/networked_board.json (oneshot_study PLANT ... FOR)"
#endif

namespace oneshot::ncs {

const char* name(Approach a) {
  switch (a) {
    case Approach::kI: return "I";
    case Approach::kS: return "S";
    case Approach::kA: return "A";
    case Approach::kAK: return "AK";
    case Approach::kAKx: return "AKx";
    case Approach::kAKl: return "AKl";
    case Approach::kSK: return "SK";
    case Approach::kSPlus: return "S+";
    case Approach::kIK: return "IK";
    case Approach::kOS: return "OS";
    case Approach::kOSp: return "OSp";
    case Approach::kOSK: return "OSK";
  }
  return "?";
}

const char* description(Approach a) {
  switch (a) {
    case Approach::kI: return "sampling-synchronized, ideal (no delay, no noise)";
    case Approach::kS: return "sampling-synchronized, delays and noise, no filter";
    case Approach::kA: return "actuation-synchronized, no filter (eq. 10)";
    case Approach::kAK: return "actuation-synchronized, half Kalman, constant Q";
    case Approach::kAKx: return "actuation-synchronized, half Kalman, exact Q_d";
    case Approach::kAKl: return "AK with late sampling at t_k - D";
    case Approach::kSK: return "sampling-synchronized, periodic Kalman";
    case Approach::kSPlus: return "sampling-synchronized, LQR on eq. 8 for the mean delay";
    case Approach::kIK: return "no delay, noise, periodic Kalman";
    case Approach::kOS: return "one-shot, event-triggered sensor, held value with inflated R";
    case Approach::kOSp: return "one-shot, event-triggered sensor, predict-only when silent";
    case Approach::kOSK: return "one-shot, sensor every sample, predict-only when missing";
  }
  return "?";
}

Approach parse_approach(const std::string& text) {
  for (Approach a : kAllApproaches)
    if (text == name(a)) return a;
  throw std::invalid_argument("ncs: unknown approach '" + text + "' (I, S, A, AK, AKx, AKl, SK, S+, IK)");
}

Approach parse_any_approach(const std::string& text) {
  for (Approach a : kOneShotApproaches)
    if (text == name(a)) return a;
  return parse_approach(text);
}

bool actuation_synchronized(Approach a) {
  return a == Approach::kA || a == Approach::kAK || a == Approach::kAKx || a == Approach::kAKl;
}

bool delay_free(Approach a) { return a == Approach::kI || a == Approach::kIK; }

std::vector<Scenario> default_scenarios() {
  // Brief §3: (A_r V, T_r s, d ms, s).
  const double rows[10][4] = {{0.2, 2, 4, 1},  {0.2, 2, 14, 1}, {0.5, 4, 8, 1},   {0.5, 2, 14, 4}, {1, 4, 4, 4},
                              {1, 2, 8, 1},    {0.2, 4, 8, 16}, {0.5, 4, 14, 16}, {1, 2, 14, 16},  {0.2, 2, 8, 4}};
  std::vector<Scenario> out;
  for (const auto& r : rows) {
    Scenario s;
    char buf[64];
    std::snprintf(buf, sizeof buf, "a%g-T%g-d%g-s%g", r[0], r[1], r[2], r[3]);
    s.name = buf;
    s.amplitude_volts = r[0];
    s.period_s = r[1];
    s.max_delay_ms = r[2];
    s.noise_scale = r[3];
    out.push_back(s);
  }
  return out;
}

std::vector<Scenario> parse_scenarios(const std::string& text, const std::string& source) {
  using engine::InputError;
  const nlohmann::json j = engine::parse_json_strict(text, source);
  std::vector<Scenario> out;
  try {
    engine::require_keys(j, "file", {"description", "scenarios"});
    const nlohmann::json& list = engine::member(j, "file", "scenarios");
    if (!list.is_array() || list.empty()) throw InputError("field 'scenarios': must be a non-empty array");
    std::set<std::string> names;
    for (std::size_t i = 0; i < list.size(); ++i) {
      const std::string where = "scenarios[" + std::to_string(i) + "]";
      const nlohmann::json& e = list[i];
      engine::require_keys(e, where, {"name", "amplitude_volts", "period_s", "max_delay_ms", "noise_scale", "duration_s"});
      Scenario s;
      s.name = engine::string_of(e, where, "name");
      if (s.name.empty() || !names.insert(s.name).second) throw InputError("field '" + where + ".name': empty or repeated");
      s.amplitude_volts = engine::number_in(e, where, "amplitude_volts", 0, 100);
      s.period_s = engine::number_in(e, where, "period_s", 1e-3, 1e6);
      s.max_delay_ms = engine::number_in(e, where, "max_delay_ms", 0.5, 1e6);
      s.noise_scale = engine::number_in(e, where, "noise_scale", 0, 1e6);
      s.duration_s = engine::number_in(e, where, "duration_s", 1e-3, 1e6, true, 20);
      out.push_back(s);
    }
  } catch (const InputError& e) {
    throw InputError(source + ": " + e.what());
  }
  return out;
}

std::vector<Scenario> load_scenarios(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw engine::InputError(path + ": cannot read the scenario file");
  std::ostringstream text;
  text << in.rdbuf();
  return parse_scenarios(text.str(), path);
}

std::string describe(const Scenario& s) {
  char buf[128];
  std::snprintf(buf, sizeof buf, "A_r %g V, T_r %g s, d %g ms, s %g, %g s", s.amplitude_volts, s.period_s,
                s.max_delay_ms, s.noise_scale, s.duration_s);
  return buf;
}

std::shared_ptr<const Context> Context::load(const std::string& plant_path) {
  return from(design::load_plant_file(plant_path.empty() ? std::string(ONESHOT_STUDY_PLANT_FILE) : plant_path));
}

std::shared_ptr<const Context> Context::load_board(const std::string& plant_path) {
  std::shared_ptr<const Context> ctx = load(plant_path);
  const design::PlantDescription& p = ctx->plant();
  if (!ctx->board()) {  // S, A, AK… and the live nodes feed y back as x: C = I (eq. 10)
    throw std::invalid_argument(p.source + ": this ncs command runs the board's plant only: n = 2, m = 1, p = 2, C = I (study files run " +
                                kNcsShapesText + ")");
  }
  return ctx;
}

std::shared_ptr<const Context> Context::from(design::PlantDescription plant) {
  auto ctx = std::make_shared<Context>();
  ctx->plant_ = std::move(plant);
  const design::PlantDescription& p = ctx->plant_;
  const std::size_t n = p.a.rows, m = p.b.cols, q = p.c.rows;
  const std::string shape = " (this one: n = " + std::to_string(n) + ", m = " + std::to_string(m) + ", p = " + std::to_string(q) + ")";
  if (!p.continuous() || !p.b_w.values.empty()) {
    throw std::invalid_argument(p.source + ": study 'ncs' needs a continuous plant of " + kNcsShapesText + " and no B_w" + shape);
  }
  if (!ncs_shape_runs(n, m, q)) {
    const char* key = n > kMaxNcsStates ? "A" : m > kMaxNcsInputs ? "B" : "C";
    throw std::invalid_argument(p.source + ": study 'ncs' runs plants of n <= 16 states, m <= 4 inputs, p <= 4 outputs; " + key +
                                " is too large" + shape);
  }
  ctx->identity_output_ = q == n;
  for (std::size_t i = 0; i < q; ++i)
    for (std::size_t j = 0; j < n; ++j)
      if (p.c(i, j) != (i == j ? 1.0 : 0.0)) ctx->identity_output_ = false;
  // The loop's cost is the continuous one (J = ∫ xᵀQ1c x + uᵀQ2c u dt over the run): a discrete cost has no Q1c, Q2c.
  if (p.cost_form != design::CostForm::kContinuous) {
    throw std::invalid_argument(p.source + ": study 'ncs' needs cost.Q1c and cost.Q2c (the loop's cost is continuous)");
  }
  ctx->design_ = design::synthesize(p);
  if (!ctx->design_.tracking) {
    throw std::invalid_argument(p.source + ": no set-point feed-forward: " + ctx->design_.tracking_unavailable_reason);
  }
  if (ctx->design_.u_min.size() != p.b.cols) throw std::invalid_argument(p.source + ": study 'ncs' needs an actuator range");
  // refuses plants without a board or LQR gain, naming why (the design of the plant's shape)
  const NcsShapeOf on = ncs_shape_of(n, m, q);
#define ONESHOT_NCS_DESIGN_OF(n_, m_, p_) \
  if (on.n == (n_) && on.m == (m_) && on.p == (p_)) (void)ctx->controller_design_of<Shape<n_, m_, p_>>(1.0);
  ONESHOT_NCS_SHAPES(ONESHOT_NCS_DESIGN_OF)
#undef ONESHOT_NCS_DESIGN_OF
  return ctx;
}

void set_steps(Scenario& sc, std::int64_t h_us, const std::vector<std::pair<double, double>>& steps,
               const std::vector<std::size_t>& lines, const std::string& source) {
  const bool by_line = lines.size() == steps.size();
  if (h_us <= 0) throw std::invalid_argument("ncs set-point steps: the period h must be positive");
  const std::int64_t h_ns = h_us * 1000;
  auto changes = std::make_shared<std::vector<std::pair<std::uint64_t, double>>>();
  double r0 = 0;
  double last = 0;  // the set-point of the period before
  std::uint64_t last_k = 0;
  for (std::size_t i = 0; i < steps.size(); ++i) {
    const double t_s = steps[i].first;
    if (!(t_s >= 0 && t_s <= 1e6)) throw std::invalid_argument("step " + std::to_string(i) + ": t_s must be in [0, 1e6] s");
    const std::int64_t t_ns = std::llround(t_s * 1e9);
    const auto k = static_cast<std::uint64_t>((t_ns + h_ns - 1) / h_ns);
    if (i > 0 && k <= last_k) {
      const std::string which = by_line ? source + " lines " + std::to_string(lines[i - 1]) + " and " + std::to_string(lines[i])
                                        : "steps " + std::to_string(i - 1) + " and " + std::to_string(i);
      throw std::invalid_argument(which + " (t_s " +
                                  std::to_string(steps[i - 1].first) + " and " + std::to_string(t_s) +
                                  " s) fall in one period h = " + std::to_string(h_us) + " us (the set-point changes on the kh grid)");
    }
    last_k = k;
    const double v = steps[i].second;
    if (k == 0) {
      r0 = v;
    } else if (v != last) {
      changes->emplace_back(k, v);
    }
    last = v;
  }
  sc.setpoint_r0 = r0;
  sc.setpoint_changes = std::move(changes);
}

std::uint64_t first_setpoint_change(const Context& ctx, const Scenario& sc) {
  if (sc.setpoint_changes) return sc.setpoint_changes->empty() ? 0 : sc.setpoint_changes->front().first;
  return sc.amplitude_volts != 0 ? half_wave_periods(ctx, sc) : 0;
}

std::uint64_t half_wave_periods(const Context& ctx, const Scenario& sc) {
  const double half = sc.period_s * 0.5e6 / ctx.period_us();
  const auto n = static_cast<std::uint64_t>(std::llround(half));
  if (n == 0 || std::fabs(half - static_cast<double>(n)) > 1e-9) {
    throw std::invalid_argument("ncs scenario " + sc.name + ": T_r/2 must be a whole number of periods h");
  }
  return n;
}

std::optional<engine::Duration> sc_ca_delay_bound(const Scenario& s, const char** unbounded_leg) {
  engine::Duration sum{0};
  for (const char* leg : {"sc", "ca"}) {
    if (s.bus_legs.count(leg) != 0) {
      if (unbounded_leg != nullptr) *unbounded_leg = leg;
      return std::nullopt;
    }
    const auto it = s.legs.find(leg);
    if (it == s.legs.end()) continue;
    const std::optional<engine::Duration> ub = it->second.delay.upper_bound();
    if (!ub) {
      if (unbounded_leg != nullptr) *unbounded_leg = leg;
      return std::nullopt;
    }
    sum += *ub;
  }
  return sum;
}

std::int32_t Context::worst_chain_us(const Scenario& s) const {
  if (legs_from_file(s)) {
    const char* leg = "";
    const std::optional<engine::Duration> sum = sc_ca_delay_bound(s, &leg);
    if (!sum) throw std::invalid_argument(std::string("ncs scenario ") + s.name + ": leg " + leg + " has no upper delay bound (late sampling needs one)");
    // τ_c's bound: the controller job's WCRT on its CPU (rounded up to whole µs), else the draw's maximum.
    const std::int64_t tau_max_us = s.controller_cpu ? (s.controller_cpu->wcrt.count() + 999) / 1000
                                    : s.compute_us   ? s.compute_us->second
                                                     : timing_.compute_max_us;
    return static_cast<std::int32_t>(std::llround(static_cast<double>(sum->count()) * 1e-3) + tau_max_us);
  }
  return static_cast<std::int32_t>(std::llround(2 * s.max_delay_ms * 1000) + timing_.compute_max_us);
}

double Context::mean_tau_io_us(const Scenario& s) const {
  if (legs_from_file(s)) {
    double sum_ns = 0;
    for (const char* leg : {"sc", "ca"}) {
      const auto it = s.legs.find(leg);
      if (it != s.legs.end()) sum_ns += it->second.delay.mean_ns();
    }
    if (s.compute_us) return sum_ns * 1e-3 + 0.5 * static_cast<double>(s.compute_us->first + s.compute_us->second);
    return sum_ns * 1e-3 + 0.5 * static_cast<double>(timing_.compute_min_us + timing_.compute_max_us);
  }
  const double leg = 0.5 * (static_cast<double>(timing_.leg_min_us) + s.max_delay_ms * 1000);
  return 2 * leg + 0.5 * static_cast<double>(timing_.compute_min_us + timing_.compute_max_us);
}

namespace {

/// Van Loan over Δ for F = [[A, B], [0, 0]], W = blkdiag(Q1c, Q2c): Φ(Δ), Γ(Δ) and the
/// Gramian G(Δ) with ∫₀^Δ [x; u]ᵀ W [x; u] = [x; u]ᵀ G [x; u] (x(0) = x, u held).
struct Segment {
  design::DenseMatrix phi, gamma, g;
};

Segment segment(const design::PlantDescription& p, double delta_s) {
  const std::size_t k = kN + kM;
  design::DenseMatrix f = design::DenseMatrix::zeros(k, k);
  design::set_block(f, 0, 0, p.a);
  design::set_block(f, 0, kN, p.b);
  design::DenseMatrix w = design::DenseMatrix::zeros(k, k);
  design::set_block(w, 0, 0, p.q1c);
  design::set_block(w, kN, kN, p.q2c);
  design::DenseMatrix v = design::DenseMatrix::zeros(2 * k, 2 * k);
  design::set_block(v, 0, 0, -design::transpose(f) * delta_s);
  design::set_block(v, 0, k, w * delta_s);
  design::set_block(v, k, k, f * delta_s);
  const design::DenseMatrix e = design::expm(v, "S+ cost segment");
  const design::DenseMatrix e22 = design::block(e, k, k, k, k);
  Segment s;
  s.phi = design::block(e22, 0, 0, kN, kN);
  s.gamma = design::block(e22, 0, kN, kN, kM);
  s.g = design::transpose(e22) * design::block(e, 0, k, k, k);
  design::symmetrize(s.g);
  return s;
}

}  // namespace

std::array<double, kN + kM> delay_compensated_gain(const Context& ctx, double tau_us) {
  const design::PlantDescription& p = ctx.plant();
  const double h = static_cast<double>(p.period_us) * 1e-6;
  const double tau = tau_us * 1e-6;
  if (!(tau >= 0 && tau < h)) throw std::invalid_argument("S+: the mean delay must lie in [0, h)");
  const Segment s1 = segment(p, tau);
  const Segment s2 = segment(p, h - tau);
  const Segment sh = segment(p, h);
  // w = [x; u_{k−1}; u_k]: [0, τ) holds u_{k−1} from x, [τ, h) holds u_k from x(τ).
  const std::size_t nw = kN + 2 * kM;
  design::DenseMatrix m1 = design::DenseMatrix::zeros(kN + kM, nw);
  for (std::size_t i = 0; i < kN + kM; ++i) m1(i, i) = 1;
  design::DenseMatrix m2 = design::DenseMatrix::zeros(kN + kM, nw);
  design::set_block(m2, 0, 0, s1.phi);
  design::set_block(m2, 0, kN, s1.gamma);
  for (std::size_t i = 0; i < kM; ++i) m2(kN + i, kN + kM + i) = 1;
  design::DenseMatrix qw = design::transpose(m1) * s1.g * m1 + design::transpose(m2) * s2.g * m2;
  design::symmetrize(qw);
  const std::size_t nx = kN + kM;
  // ξ_{k+1} = [[Φ(h), Φ(h−τ)Γ(τ)], [0, 0]] ξ_k + [Γ(h−τ); I] u_k   (eq. 8 corrected)
  design::DenseMatrix a = design::DenseMatrix::zeros(nx, nx);
  design::set_block(a, 0, 0, sh.phi);
  design::set_block(a, 0, kN, s2.phi * s1.gamma);
  design::DenseMatrix b = design::DenseMatrix::zeros(nx, kM);
  design::set_block(b, 0, 0, s2.gamma);
  for (std::size_t i = 0; i < kM; ++i) b(kN + i, i) = 1;
  const design::DareSolution sol =
      design::solve_dare(a, b, design::block(qw, 0, 0, nx, nx), design::block(qw, nx, nx, kM, kM),
                         design::block(qw, 0, nx, nx, kM));
  if (sol.status != design::DareStatus::kOk) {
    throw std::runtime_error(std::string("S+: the Riccati equation of eq. 8 failed: ") + design::to_string(sol.status));
  }
  // L = (R + BᵀXB)⁻¹ (BᵀXA + Sᵀ)
  const design::DenseMatrix bt = design::transpose(b);
  const design::SolveResult l = design::solve(design::block(qw, nx, nx, kM, kM) + bt * sol.x * b,
                                              bt * sol.x * a + design::transpose(design::block(qw, 0, nx, nx, kM)));
  if (!l.ok) throw std::runtime_error("S+: singular gain equation");
  std::array<double, kN + kM> out{};
  for (std::size_t j = 0; j < nx; ++j) out[j] = l.x(0, j);
  return out;
}

SplitGain delay_compensated_split(const Context& ctx, double tau_us) {
  const auto g = delay_compensated_gain(ctx, tau_us);
  SplitGain s;
  for (std::size_t j = 0; j < kN; ++j) s.lx(0, j) = g[j];
  s.lu(0, 0) = g[kN];
  return s;
}

}  // namespace oneshot::ncs
