/// @file ncs_stationary.cpp
/// @brief Study ncs, stationary cost for i.i.d. delays (see ncs_stationary.hpp).
#include "ncs_stationary.hpp"

#include <cmath>
#include <filesystem>
#include <iostream>
#include <map>
#include <memory>
#include <sstream>
#include <stdexcept>

#include <CLI/CLI.hpp>

#include "ncs_analytic.hpp"
#include "ncs_live.hpp"
#include "ncs_live_nodes.hpp"
#include "ncs_loop.hpp"
#include "oneshot/engine/stationary_cost.hpp"
#include "oneshot/node/sampling_sync_laws.hpp"
#include "oneshot/node/sync_estimators.hpp"
#include "oneshot/plant_structure.hpp"
#include "oneshot/util/file_io.hpp"
#include "oneshot/util/number_text.hpp"
#include "oneshot/util/output_files.hpp"
#include "oneshot/util/parallel.hpp"
#include "oneshot/util/statistics.hpp"

namespace oneshot::ncs {
namespace {

using Structure = DenseStructure<kN, kM, kP>;
using Ref = SetpointReference;
using InputVec = Vector<double, kM>;
using OutputVec = Vector<double, kP>;
using Outcome = engine::PeriodOutcome<kZ>;
using engine::from_us;
using engine::SimTime;

/// The period's outcome read off the tracker; a refusal inside a probe is an error here.
Outcome outcome(const AnalyticTracker& t) {
  if (!t.refusal().empty()) throw std::logic_error("ncs stationary: a probe period was refused: " + t.refusal());
  return {t.covariance(), t.cost().covariance + t.cost().noise_path};
}

/// The stationary cost of the cases of `pmf`, each period run by `period(τ_us, Σ)`.
/// `live` marks the entries of z the loop uses (empty: all).
template <typename Period>
StationaryRow solve(const DelayPmf& pmf, std::int32_t h_us, Period&& period, std::vector<bool> live = {}) {
  const std::vector<double> len(pmf.p.size(), static_cast<double>(h_us) * 1e-6);
  const engine::StationaryCost st = engine::stationary_cost<kZ>(
      pmf.p, len, [&](std::size_t i, const Matrix<double, kZ, kZ>& s) { return period(pmf.tau_us[i], s); }, std::move(live));
  return {st.cost_rate, st.spectral_radius, st.residual, pmf.p.size()};
}

/// A sampling loop (S, S+, SK, IK): sample at kh, the law on it, applied at kh + τ.
template <typename Law>
StationaryRow sampling_row(AnalyticTracker& t, const Law& law, const DelayPmf& pmf, std::int32_t h_us) {
  return solve(pmf, h_us, [&](std::int64_t tau_us, const Matrix<double, kZ, kZ>& s) {
    t.restart(SimTime{0}, AnalyticTracker::Z{}, s);
    t.sample(SimTime{0}, OutputVec{});
    t.flow_to(from_us(tau_us));
    t.compute_law(law, 0);
    t.apply(InputVec{});
    t.flow_to(from_us(h_us));
    return outcome(t);
  });
}

/// The synchronized controller's memory is x̂ (two entries): z's third memory slot is unused.
std::vector<bool> dead_third_memory_slot() {
  std::vector<bool> live(kZ, true);
  live[kZmem + 2] = false;
  return live;
}

/// The actuation-synchronized predictor (A): sample at τ_as after t_{k−1}, eq. 10 over h − τ_as, applied at t_k.
template <typename Pred>
StationaryRow synchronized_row(AnalyticTracker& t, const Pred& pred, const DelayPmf& pmf, std::int32_t h_us) {
  return solve(pmf, h_us, [&](std::int64_t tau_as_us, const Matrix<double, kZ, kZ>& s) {
    t.restart(SimTime{0}, AnalyticTracker::Z{}, s);
    t.flow_to(from_us(tau_as_us));
    t.sample(from_us(tau_as_us), OutputVec{});
    Pred after = pred;
    if (after.update(static_cast<std::int32_t>(h_us - tau_as_us), OutputVec{}, InputVec{}) != Status::kOk)
      throw std::logic_error("ncs stationary: the predictor refused τ = " + std::to_string(h_us - tau_as_us) + " µs");
    t.compute_sync(pred, after, h_us, Vector<double, kN>{}, InputVec{}, InputVec{});
    t.flow_to(from_us(h_us));
    t.apply(InputVec{});
    return outcome(t);
  }, dead_third_memory_slot());
}

}  // namespace

DelayPmf uniform_sum_pmf(const std::vector<std::pair<std::int64_t, std::int64_t>>& ranges, std::int64_t grid_us) {
  if (grid_us < 1) throw std::invalid_argument("ncs stationary: grid must be at least 1 µs");
  // pmf over [lo, lo + size): start with the point mass at 0.
  std::int64_t lo = 0;
  std::vector<double> pmf = {1.0};
  for (const auto& [a, b] : ranges) {
    if (a < 0 || b < a) throw std::invalid_argument("ncs stationary: a delay range must satisfy 0 <= min <= max");
    const auto w = static_cast<std::size_t>(b - a + 1);
    // (pmf * U{0 … w−1})[t] = (C[t] − C[t − w]) / w with C the running sum of pmf.
    std::vector<double> c(pmf.size() + 1, 0.0);
    for (std::size_t i = 0; i < pmf.size(); ++i) c[i + 1] = c[i] + pmf[i];
    std::vector<double> next(pmf.size() + w - 1);
    for (std::size_t t = 0; t < next.size(); ++t) {
      const std::size_t hi = std::min(t + 1, pmf.size());
      const std::size_t low = t + 1 >= w ? t + 1 - w : 0;
      next[t] = (c[hi] - c[low]) / static_cast<double>(w);
    }
    pmf = std::move(next);
    lo += a;
  }
  std::map<std::int64_t, double> grid;
  for (std::size_t i = 0; i < pmf.size(); ++i) {
    if (pmf[i] <= 0) continue;
    const std::int64_t tau = lo + static_cast<std::int64_t>(i);
    const std::int64_t below = tau / grid_us * grid_us;
    const std::int64_t rem = tau - below;
    if (2 * rem < grid_us) {
      grid[below] += pmf[i];
    } else if (2 * rem > grid_us) {
      grid[below + grid_us] += pmf[i];
    } else {  // a tie: half to each neighbour, so the grid keeps the mean
      grid[below] += 0.5 * pmf[i];
      grid[below + grid_us] += 0.5 * pmf[i];
    }
  }
  DelayPmf r;
  for (const auto& [tau, p] : grid) {
    r.tau_us.push_back(tau);
    r.p.push_back(p);
  }
  return r;
}

DelayPmf timing_pmf(const Context& ctx, const Scenario& sc, Approach a, std::int64_t grid_us) {
  const Timing& t = ctx.timing();
  const std::pair<std::int64_t, std::int64_t> leg{t.leg_min_us, std::llround(sc.max_delay_ms * 1000)};
  if (delay_free(a)) return uniform_sum_pmf({}, grid_us);
  if (actuation_synchronized(a)) return uniform_sum_pmf({leg}, grid_us);
  return uniform_sum_pmf({leg, {t.compute_min_us, t.compute_max_us}, leg}, grid_us);
}

std::string stationary_refusal(Approach a) {
  switch (a) {
    case Approach::kI:
      return "I has no noise: its stationary noise cost is 0";
    case Approach::kAK:
    case Approach::kAKx:
    case Approach::kAKl:
      return std::string(name(a)) + ": the half Kalman filter's gain depends on the delay history (its P), "
             "so the loop is not jump-linear with i.i.d. modes";
    default:
      return "";
  }
}

StationaryRow stationary_row(const Context& ctx, const Scenario& sc, Approach a, std::int64_t grid_us) {
  if (const std::string why = stationary_refusal(a); !why.empty()) throw std::invalid_argument(why);
  const std::int32_t h_us = ctx.period_us();
  const DelayPmf pmf = timing_pmf(ctx, sc, a, grid_us);
  if (pmf.tau_us.back() >= h_us)
    throw std::invalid_argument("ncs stationary: scenario " + sc.name + " has delays up to " +
                                std::to_string(pmf.tau_us.back()) + " µs, not below the period (late commands)");
  Scenario flat = sc;  // the noise-driven part: set-point zero
  flat.amplitude_volts = 0;
  flat.setpoint_changes.reset();  // a stepped set-point too
  flat.setpoint_r0 = 0;
  const Design d = ctx.controller_design(sc.noise_scale);
  const Disc disc(ctx.discretizer_model(sc.noise_scale));
  const Ref ref = reference(ctx, flat);
  const live::InputRange range = live::actuator_range(ctx);
  const InputVec& u_min = range.lo;
  const InputVec& u_max = range.hi;
  const auto tracker = make_tracker(ctx, flat, a, d, RunOptions{}, Vector<double, kN>{}, InputVec{});
  switch (a) {
    case Approach::kA:
      return synchronized_row(*tracker, node::SampledStatePredictor<Fmt, Structure, Disc>(disc), pmf, h_us);
    case Approach::kS:
      return sampling_row(*tracker, node::StateFeedbackLaw<double, kN, kM, Ref>{d.l, u_min, u_max, ref}, pmf, h_us);
    case Approach::kSPlus: {
      const SplitGain g = delay_compensated_split(ctx, ctx.mean_tau_io_us(sc));
      return sampling_row(*tracker, node::DelayCompensatedLaw<double, kN, kM, Ref>{g.lx, g.lu, u_min, u_max, ref}, pmf, h_us);
    }
    case Approach::kSK:
    case Approach::kIK: {
      // The periodic filter's P does not depend on the data: run it to its stationary gain.
      node::PeriodicKalmanLaw<Fmt, Structure, Ref> law(d, NoiseModel::kConstant, u_min, u_max, ref);
      law.filter().reset(Vector<double, kN>{}, d.p0, InputVec{});
      node::Message<node::VectorPayload<double, kN>> m{};
      InputVec u{};
      double change = 1;
      for (std::uint32_t k = 0; k < 100000 && change > 0; ++k) {
        const auto before = law.filter().covariance();
        m.seq = k;
        (void)law.compute(m, true, McuInstant{}, u);
        change = 0;
        for (std::size_t i = 0; i < kN; ++i)
          for (std::size_t j = 0; j < kN; ++j) change = std::fmax(change, std::fabs(law.filter().covariance()(i, j) - before(i, j)));
      }
      if (change > 0) throw std::logic_error("ncs stationary: the periodic Kalman filter's P did not settle");
      return sampling_row(*tracker, law, pmf, h_us);
    }
    default:
      break;
  }
  throw std::logic_error("ncs stationary: unhandled approach");
}

std::pair<double, double> long_run_rate(const Context& ctx, const Scenario& sc, Approach a, std::uint64_t first_seed,
                                        std::size_t seeds, double warm_s, double span_s, unsigned threads) {
  std::vector<double> rates(seeds);
  util::parallel_for(seeds, threads, nullptr, [&](std::size_t i) {
    RunOptions o;
    o.analytic = true;
    o.analytic_mark_s = warm_s;  // E[J](T₁) from the same run: the warm-up is simulated once
    Scenario s = sc;
    s.duration_s = warm_s + span_s;
    const RunResult r = run(ctx, a, s, first_seed + i, o);
    if (!r.analytic_refusal.empty()) throw std::runtime_error("ncs stationary check: run refused: " + r.analytic_refusal);
    const auto noise_part = [](const engine::ExpectedCost& c) { return c.covariance + c.noise_path; };
    rates[i] = (noise_part(r.analytic) - noise_part(r.analytic_at_mark)) / span_s;
  });
  const util::Summary s = util::summarize(rates);
  return {s.mean, s.ci95};
}

nlohmann::json stationary_table(const Context& ctx, const StationaryOptions& o) {
  struct Cell {
    StationaryRow row;
    std::string refused;
    std::pair<double, double> check{0, 0};
  };
  const std::size_t na = o.approaches.size();
  std::vector<Cell> cells(o.scenarios.size() * na);
  util::parallel_for(cells.size(), o.threads, nullptr, [&](std::size_t i) {
    const Scenario& sc = o.scenarios[i / na];
    const Approach a = o.approaches[i % na];
    Cell& c = cells[i];
    c.refused = stationary_refusal(a);
    if (!c.refused.empty()) return;
    c.row = stationary_row(ctx, sc, a, o.grid_us);
    if (o.check_seeds > 0) c.check = long_run_rate(ctx, sc, a, o.seed, o.check_seeds, o.check_warm_s, o.check_span_s, 1);
  });
  nlohmann::json j;
  j["grid_us"] = o.grid_us;
  j["check"] = {{"seeds", o.check_seeds}, {"warm_s", o.check_warm_s}, {"span_s", o.check_span_s}, {"first_seed", o.seed}};
  std::ostringstream md;
  md << "| scenario |";
  for (Approach a : o.approaches) md << ' ' << name(a) << " |";
  md << "\n|---|";
  for (std::size_t k = 0; k < na; ++k) md << "---|";
  md << '\n';
  double worst_sigma = 0;  // largest |stationary − long run| in 95 % half-widths (cells with a timing spread)
  for (std::size_t s = 0; s < o.scenarios.size(); ++s) {
    nlohmann::json row;
    row["scenario"] = o.scenarios[s].name;
    md << "| " << o.scenarios[s].name << " |";
    for (std::size_t k = 0; k < na; ++k) {
      const Cell& c = cells[s * na + k];
      nlohmann::json cj;
      if (!c.refused.empty()) {
        cj["refused"] = c.refused;
        md << " — |";
      } else {
        cj["stationary_cost_rate"] = c.row.cost_rate;
        cj["spectral_radius"] = c.row.spectral_radius;
        cj["residual"] = c.row.residual;
        cj["cases"] = c.row.cases;
        md << ' ' << util::format_f(c.row.cost_rate, 6);
        if (o.check_seeds > 0) {
          cj["long_run_rate_mean"] = c.check.first;
          cj["long_run_rate_ci95"] = c.check.second;
          // A loop without timing spread (IK) has a zero-width interval: rounding (1e-9 relative) allowed.
          const double slack = 1e-9 * std::fabs(c.check.first);
          const double dist = std::fabs(c.row.cost_rate - c.check.first);
          cj["stationary_inside_long_run_ci95"] = dist <= c.check.second + slack;
          if (c.check.second > slack) worst_sigma = std::fmax(worst_sigma, dist / c.check.second);
          md << " (" << util::format_f(c.check.first, 6) << " ± " << util::format_f(c.check.second, 6) << ')';
        }
        md << " |";
      }
      row["approaches"][name(o.approaches[k])] = cj;
    }
    md << '\n';
    j["scenarios"].push_back(row);
  }
  j["worst_distance_in_ci95"] = worst_sigma;
  j["markdown"] = md.str();
  return j;
}

}  // namespace oneshot::ncs

namespace oneshot::sim {

void add_ncs_stationary_command(CLI::App* study) {
  auto o = std::make_shared<ncs::StationaryOptions>();
  auto plant = std::make_shared<std::string>();
  auto scenario_file = std::make_shared<std::string>();
  auto approaches = std::make_shared<std::vector<std::string>>();
  auto out = std::make_shared<std::string>("out/ncs-stationary");
  auto json = std::make_shared<std::string>();
  CLI::App* cmd = study->add_subcommand(
      "stationary", "Stationary noise cost per second for i.i.d. delays (Jitterbug method) of IK, A, S+, SK, S, "
                    "beside long analytic runs of the same loops");
  cmd->add_option("--grid-us", o->grid_us, "grid of the delay distribution (µs)")->check(CLI::Range(1, 10000))->capture_default_str();
  cmd->add_option("--check-seeds", o->check_seeds, "long analytic runs per cell (0: no check)")->check(CLI::Range(0, 1000))
      ->capture_default_str();
  cmd->add_option("--check-span", o->check_span_s, "seconds of each long run after its warm-up")->check(CLI::Range(1.0, 36000.0))
      ->capture_default_str();
  cmd->add_option("--check-warm", o->check_warm_s, "warm-up seconds of each long run")->check(CLI::Range(1.0, 3600.0))
      ->capture_default_str();
  cmd->add_option("--seed", o->seed, "first seed of the check")->capture_default_str();
  cmd->add_option("--threads", o->threads, "worker threads (0: every core)")->capture_default_str();
  cmd->add_option("--approaches", *approaches, "approaches (default: IK A S+ SK S)");
  cmd->add_option("--scenarios", *scenario_file, "scenario file (default: the ten of the brief)")->check(CLI::ExistingFile);
  cmd->add_option("--plant", *plant, "plant file (default: lut_gen/plants/networked_board.json)")->check(CLI::ExistingFile);
  cmd->add_option("--out", *out, "output directory (stationary.md)")->capture_default_str();
  cmd->add_option("--json", *json, "write the result as JSON to PATH, or '-' for standard output");
  cmd->callback([o, plant, scenario_file, approaches, out, json]() {
    if (!scenario_file->empty()) o->scenarios = ncs::load_scenarios(*scenario_file);
    if (!approaches->empty()) {
      o->approaches.clear();
      for (const std::string& a : *approaches) {
        const ncs::Approach ap = ncs::parse_approach(a);
        if (const std::string why = ncs::stationary_refusal(ap); !why.empty()) throw std::invalid_argument("ncs stationary: " + why);
        o->approaches.push_back(ap);
      }
    }
    const auto ctx = ncs::Context::load_board(*plant);
    nlohmann::json j = ncs::stationary_table(*ctx, *o);
    j["experiment"] = "stationary";
    util::create_directories(*out);
    util::write_text((std::filesystem::path(*out) / "stationary.md").string(), j.at("markdown").get<std::string>());
    if (*json != "-") std::cout << j.at("markdown").get<std::string>() << "written to " << *out << "/stationary.md\n";
    if (!json->empty()) util::write_json(*json, j);
  });
}

}  // namespace oneshot::sim
