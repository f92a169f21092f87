/// @file ncs_analytic.cpp
/// @brief Study ncs, analytic mode: the tracker's sample and apply maps and its checks
///        (see ncs_analytic.hpp).
#include "ncs_analytic.hpp"

#include <iterator>

namespace oneshot::ncs {

namespace {

constexpr const char* kClamp = "the noise-free trajectory reaches the actuator's clamp";
constexpr const char* kLate = "a command was late (held)";
constexpr const char* kInexact = "an estimator run was not exact";
constexpr const char* kFaults = "faults injected (--inject): the loop is not the linear one";
constexpr const char* kMismatch = "the analytic mean left the simulated trajectory";
constexpr const char* kTwoSamples = "two samples in flight before a computation";
constexpr const char* kNoSample = "a computation without a new sample";
constexpr const char* kTwice = "a command applied twice";
/// Every reason, by code (1 …).
constexpr const char* kReasons[] = {kClamp, kLate, kInexact, kFaults, kMismatch, kTwoSamples, kNoSample, kTwice};

}  // namespace

int analytic_refusal_code(const std::string& reason) {
  if (reason.empty()) return 0;
  for (std::size_t i = 0; i < std::size(kReasons); ++i)
    if (reason == kReasons[i]) return static_cast<int>(i) + 1;
  return static_cast<int>(std::size(kReasons)) + 1;
}

const char* analytic_refusal_text(int code) {
  if (code <= 0) return "";
  if (static_cast<std::size_t>(code) <= std::size(kReasons)) return kReasons[code - 1];
  return "unknown";
}

std::array<double, std::size(kAnalyticMetrics)> analytic_metrics(const Context& ctx, Approach a, const Scenario& sc,
                                                                  std::uint64_t seed, RunOptions options) {
  options.analytic = true;
  const RunResult x = run(ctx, a, sc, seed, options);
  const int code = analytic_refusal_code(x.analytic_refusal);
  return {code == 0 ? x.analytic.total() : 0.0, static_cast<double>(code), x.analytic_mismatch};
}

AnalyticTracker::AnalyticTracker(const engine::JumpLinearPlant<kN, kM>& plant, const Matrix<double, kP, kN>& c,
                                 const Matrix<double, kP, kP>& r, const Matrix<double, kM, kN>& l,
                                 const Vector<double, kN>& x0, const Vector<double, kN>& mem0)
    : jl_(plant), c_(c), r_(r), l_(l) {
  Z m{};
  for (std::size_t i = 0; i < kN; ++i) {
    m[kZx + i] = x0[i];
    m[kZmem + i] = mem0[i];
  }
  jl_.reset(m, Jlc::Cov{});
}

void AnalyticTracker::flow_to(engine::SimTime t) {
  jl_.flow(t - now_);
  now_ = t;
}

void AnalyticTracker::sample(engine::SimTime t, const Vector<double, kP>& y_sim) {
  if (y_fresh_) refuse(kTwoSamples);
  // y ← C x + v.
  Map e = Map::identity();
  Matrix<double, kZ, kP> f;
  for (std::size_t i = 0; i < kP; ++i) {
    e(kZy + i, kZy + i) = 0;
    for (std::size_t j = 0; j < kN; ++j) e(kZy + i, kZx + j) = c_(i, j);
    f(kZy + i, i) = 1;
  }
  jl_.jump(e, f, Z{}, r_);
  for (std::size_t i = 0; i < kP; ++i) check(jl_.mean()[kZy + i], y_sim[i]);
  y_fresh_ = true;
  last_sample_us_ = t.count() / 1000;
}

void AnalyticTracker::apply(const Vector<double, kM>& u_sim) {
  if (computed_ && !cmd_fresh_) refuse(kTwice);
  // u ← command; echo ← u.
  Map e = Map::identity();
  e(kZu, kZu) = 0;
  e(kZu, kZcmd) = 1;
  e(kZecho, kZecho) = 0;
  e(kZecho, kZcmd) = 1;
  jl_.jump(e, Z{});
  check(jl_.mean()[kZu], u_sim[0]);
  cmd_fresh_ = false;
}

bool AnalyticTracker::take_sample() {
  computed_ = true;
  if (!y_fresh_) {
    refuse(kNoSample);
    return false;
  }
  y_fresh_ = false;
  return true;
}

void AnalyticTracker::check(double mean, double sim) {
  const double d = std::fabs(mean - sim) / std::fmax(1.0, std::fabs(sim));
  mismatch_ = std::fmax(mismatch_, d);
  if (!(d <= 1e-9)) refuse(kMismatch);
}

std::unique_ptr<AnalyticTracker> make_tracker(const Context& ctx, const Scenario& sc, Approach a, const Design& d,
                                              const RunOptions& opt, const Vector<double, kN>& x0,
                                              const Vector<double, kM>& u_ref0) {
  const bool noisy = !opt.noise_free && a != Approach::kI;
  const auto pc = plant_config(ctx, sc, noisy);
  const engine::JumpLinearPlant<kN, kM> jp{pc.a, pc.b, noisy ? pc.qc : Matrix<double, kN, kN>{}, pc.q1c, pc.q2c};
  // The memory starts as the nodes' objects do: x̂ = x0 (estimators), S+'s u_{k−1} = 0.
  const bool filter = actuation_synchronized(a) || a == Approach::kSK || a == Approach::kIK;
  const Vector<double, kN> mem0 = filter ? x0 : Vector<double, kN>{};
  auto t = std::make_unique<AnalyticTracker>(jp, pc.c, noisy ? d.r : Matrix<double, kP, kP>{}, d.l, x0, mem0);
  t->set_reference(x0, u_ref0);
  if (!opt.faults.empty()) t->refuse(kFaults);
  return t;
}

void refuse_nonlinear_runs(RunResult& r) {
  // These causes come first: they explain the tracker's own refusals (a clamped command
  // takes the mean off the simulated trajectory), unless the approach is not supported at all.
  if (r.analytic_refusal == kFaults) return;
  if (r.saturated > 0) r.analytic_refusal = kClamp;
  else if (r.late > 0) r.analytic_refusal = kLate;
  else if (r.faults > 0) r.analytic_refusal = kInexact;
}

}  // namespace oneshot::ncs
