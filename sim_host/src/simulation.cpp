/// @file simulation.cpp
/// @brief Closed-loop runs (see simulation.hpp).
#include "oneshot/sim/simulation.hpp"

#include <cmath>
#include <cstring>
#include <functional>
#include <stdexcept>
#include <type_traits>

#include "oneshot/app/control_task.hpp"
#include "oneshot/complete_kalman.hpp"
#include "oneshot/controller.hpp"
#include "oneshot/deadbeat_observer.hpp"
#include "oneshot/fixed_point.hpp"
#include "oneshot/design/dimension_dispatch.hpp"
#include "oneshot/design/fixed_size.hpp"
#include "oneshot/design/structure_analysis.hpp"
#include "oneshot/generated/plant_tables.hpp"
#include "oneshot/generic_discretizer.hpp"
#include "oneshot/half_kalman.hpp"
#include "oneshot/host/host_board.hpp"
#include "oneshot/plant_structure.hpp"
#include "oneshot/sim/pil_link.hpp"
#include "oneshot/standard_kalman.hpp"
#include "oneshot/table_discretizer.hpp"

namespace oneshot::sim {

const char* to_string(NumberFormat f) {
  switch (f) {
    case NumberFormat::kFloat: return "float";
    case NumberFormat::kDouble: return "double";
    case NumberFormat::kFixed: return "fixed";
  }
  return "?";
}

const char* to_string(DiscretizerKind d) {
  switch (d) {
    case DiscretizerKind::kTable: return "table";
    case DiscretizerKind::kNearest: return "nearest";
    case DiscretizerKind::kGeneric: return "generic";
  }
  return "?";
}

Approach parse_approach(const std::string& letter) {
  if (letter.size() == 1) {
    for (Approach a : kAllApproaches)
      if (std::toupper(static_cast<unsigned char>(letter[0])) == info(a).letter) return a;
  }
  throw std::invalid_argument("unknown approach '" + letter + "' (A, B, C, D or E)");
}

std::shared_ptr<const SimContext> SimContext::reference() {
  auto ctx = std::make_shared<SimContext>(SimContext{});
  ctx->plant_ = design::reference_plant();
  ctx->design_ = design::synthesize(ctx->plant_);
  ctx->generated_ = true;
  const auto patterns = design::analyse_structure(ctx->plant_, ctx->design_);
  ctx->table_float_ = design::build_table<float>(ctx->plant_, ctx->design_, patterns);
  ctx->table_double_ = design::build_table<double>(ctx->plant_, ctx->design_, patterns);
  return ctx;
}

std::shared_ptr<const SimContext> SimContext::from_plant(design::PlantDescription plant) {
  auto ctx = std::make_shared<SimContext>(SimContext{});
  ctx->plant_ = std::move(plant);
  design::require_continuous_board_and_table(ctx->plant_, "the one-shot harness");
  ctx->design_ = design::synthesize(ctx->plant_);
  if (!ctx->design_.tracking) {
    throw design::DesignError(ctx->plant_.source + ": the harness needs set-point feed-forward (as many outputs as "
                              "inputs and a unique equilibrium)");
  }
  const auto patterns = design::analyse_structure(ctx->plant_, ctx->design_);
  ctx->table_float_ = design::build_table<float>(ctx->plant_, ctx->design_, patterns);
  ctx->table_double_ = design::build_table<double>(ctx->plant_, ctx->design_, patterns);
  return ctx;
}

std::shared_ptr<const SimContext> SimContext::load(const std::string& path) {
  return path.empty() ? reference() : from_plant(design::load_plant_file(path));
}

namespace {

template <typename T, typename = void>
struct HasGain : std::false_type {};
template <typename T>
struct HasGain<T, std::void_t<decltype(std::declval<const T&>().gain())>> : std::true_type {};

template <typename S>
double to_double(S v) {
  return ScalarTraits<S>::to_double(v);
}

/// What the loop reads back from a job.
template <std::size_t N>
struct JobReport {
  std::int32_t tau_us = 0;
  double estimate[N] = {};
  double gain0 = 0;
  double u_applied = 0;
};

/// The firmware's control task run in-process through the host port.
template <typename Ctrl, app::TaskModel kModel>
class LocalDriver {
 public:
  static constexpr std::size_t kN = Ctrl::kN;
  explicit LocalDriver(Ctrl& ctrl) : ctrl_(&ctrl), task_(ctrl) {}
  template <std::size_t M>
  void reset(const std::int32_t (&codes)[M], double p0_scale) {
    typename Ctrl::InputVec u0;
    for (std::size_t j = 0; j < M; ++j) u0[j] = input_of_code(ctrl_->design().actuator, j, codes[j]);
    // P0 scaled entry by entry in double (a fixed covariance format cannot hold the factor).
    auto p0 = ctrl_->design().p0;
    using CovScalar = typename Ctrl::CovScalar;
    for (std::size_t k = 0; k < p0.kSize; ++k) {
      p0[k] = ScalarTraits<CovScalar>::from_double(ScalarTraits<CovScalar>::to_double(p0[k]) * p0_scale);
    }
    clear_saturation_flag();
    ctrl_->estimator().reset(typename Ctrl::StateVec{}, p0, u0);
    task_.reset();
  }
  void actuation(host::HostBoardState&) { task_.on_actuation_interrupt(); }
  JobReport<kN> job(host::HostBoardState&) {
    task_.run_job();
    JobReport<kN> r;
    r.tau_us = task_.statistics().last_tau_us;
    for (std::size_t i = 0; i < kN; ++i) r.estimate[i] = to_double(ctrl_->estimator().prediction()[i]);
    if constexpr (HasGain<typename Ctrl::EstimatorType>::value) r.gain0 = to_double(ctrl_->estimator().gain()[0]);
    r.u_applied = to_double(ctrl_->applied_input()[0]);
    return r;
  }
  const app::TaskStatistics& statistics() const { return task_.statistics(); }
  bool saturated() const { return saturation_flag(); }

 private:
  Ctrl* ctrl_;
  app::ControlTask<host::HostBoard, Ctrl, kModel> task_;
};

/// Decodes a raw 32-bit value of the firmware (IEEE bits, or a fixed mantissa) in format T.
template <typename T>
double decode_raw(std::uint32_t raw) {
  if constexpr (kIsFloating<T>) {
    static_assert(sizeof(T) == 4, "the firmware reports single precision");
    float f = 0;
    std::memcpy(&f, &raw, 4);
    return static_cast<double>(f);
  } else {
    using Storage = typename T::StorageType;
    return ScalarTraits<T>::to_double(T::from_raw(static_cast<Storage>(static_cast<std::int32_t>(raw))));
  }
}

/// The firmware's control task run in QEMU, behind the PIL link.
template <typename Fmt, std::size_t N, std::size_t M, std::size_t P, app::TaskModel kModel>
class RemoteDriver {
 public:
  RemoteDriver(PilLink& link, Approach approach, NoiseModel noise) : link_(&link), approach_(approach), noise_(noise) {}
  void reset(const std::int32_t (&codes)[M], double p0_scale) {
    if (p0_scale != 1.0) throw std::invalid_argument("PIL runs start from the design's initial covariance (p0 scale 1)");
    app::pil::Frame f;
    app::pil::Writer w(f);
    w.u(static_cast<std::uint32_t>(approach_), 1);
    w.u(noise_ == NoiseModel::kExact ? 1U : 0U, 1);
    for (std::size_t j = 0; j < M; ++j) w.u(static_cast<std::uint32_t>(codes[j]), 2);
    link_->request(app::pil::Type::kConfig, f);
    stats_ = app::TaskStatistics{};
    saturated_ = false;
  }
  void actuation(host::HostBoardState& b) {
    app::pil::Frame f;
    app::pil::Writer w(f);
    w.u(b.now_us, 4);
    const app::pil::Frame r = link_->request(app::pil::Type::kTick, f);
    app::pil::Reader in(r);
    const std::size_t writes = read_writes(in, b);
    if (kModel == app::TaskModel::kOneShot && writes == 0 && stats_.jobs > 0) ++stats_.overruns;
  }
  JobReport<N> job(host::HostBoardState& b) {
    const std::uint32_t t_apply = kModel == app::TaskModel::kOneShot ? b.next_actuation_us : b.now_us;
    app::pil::Frame f;
    app::pil::Writer w(f);
    w.u(b.now_us, 4);
    w.u(b.next_actuation_us, 4);
    for (std::size_t o = 0; o < P; ++o) w.s(b.adc_codes[o], 2);
    for (std::size_t o = 0; o < P; ++o) w.s(b.setpoint_at(b.setpoint_context, o, t_apply), 2);
    const app::pil::Frame r = link_->request(app::pil::Type::kSample, f);
    app::pil::Reader in(r);
    const auto status = static_cast<Status>(in.u(1));
    JobReport<N> rep;
    rep.tau_us = in.s(4);
    if (in.u(1) != 0U) saturated_ = true;
    read_writes(in, b);
    double u[M] = {};
    for (std::size_t j = 0; j < M; ++j) u[j] = decode_raw<typename Fmt::Input>(in.u(4));
    rep.u_applied = u[0];
    for (std::size_t i = 0; i < N; ++i) rep.estimate[i] = decode_raw<typename Fmt::State>(in.u(4));
    rep.gain0 = decode_raw<typename Fmt::KalmanGain>(in.u(4));
    if (in.bad()) throw PilError("PIL: short job reply");
    ++stats_.jobs;
    stats_.last_tau_us = rep.tau_us;
    stats_.last_status = status;
    if (!is_exact(status)) ++stats_.faults;
    return rep;
  }
  const app::TaskStatistics& statistics() const { return stats_; }
  bool saturated() const { return saturated_; }

 private:
  static std::size_t read_writes(app::pil::Reader& in, host::HostBoardState& b) {
    const std::size_t n = in.u(1);
    for (std::size_t i = 0; i < n; ++i) {
      const std::size_t ch = in.u(1);
      const auto code = static_cast<std::int32_t>(in.u(2));
      b.pwm_writes.push_back(host::PwmWrite{ch, code, b.now_us});
    }
    return n;
  }

  PilLink* link_;
  Approach approach_;
  NoiseModel noise_;
  app::TaskStatistics stats_{};
  bool saturated_ = false;
};

/// The closed loop around a driver (LocalDriver, or RemoteDriver for the MCU).
template <std::size_t N, std::size_t M, std::size_t P, app::TaskModel kModel, typename Driver>
RunResult run_loop(const SimContext& ctx, const Scenario& sc, std::uint64_t seed, const RunOptions& opt,
                   Driver& driver) {
  const design::PlantDescription& plant = ctx.plant();
  const design::DesignResult& d = ctx.design();
  const JitterModel jitter = info(opt.approach).jitter ? sc.jitter : JitterModel{};
  BoardEmulator<N, M, P> emu(circuit_config<N, M, P>(plant, d, opt.board), RandomStream(seed, "process"));
  RandomStream jitter_rng(seed, "jitter");
  RandomStream measurement_rng(seed, "measurement");
  const SetpointSchedule schedule = make_schedule(sc, plant, seed);
  const auto code_volts = [&](std::int32_t code) { return d.y_offset[0] + code * d.volts_per_code[0]; };
  const auto setpoint_at = [&](std::int64_t t_ns) {
    Vector<double, P> r;
    for (std::size_t o = 0; o < P; ++o) r[o] = code_volts(schedule.code_at(t_ns));
    return r;
  };

  // Initial conditions: circuit at rest, PWM at the code nearest 0 V, estimator agreeing.
  for (std::size_t j = 0; j < M; ++j) {
    const auto code = static_cast<std::int32_t>(std::lround(-d.u_min[j] * d.steps_per_volt[j]));
    emu.set_duty(j, code);
  }
  emu.set_setpoint(setpoint_at(0));
  std::int32_t initial_codes[M] = {};
  for (std::size_t j = 0; j < M; ++j) initial_codes[j] = emu.duty(j);
  driver.reset(initial_codes, opt.p0_scale);

  host::HostBoardState board;
  board.adc_codes.assign(P, 0);
  board.setpoint_context = &schedule;
  board.setpoint_at = [](const void* c, std::size_t, std::uint32_t at_us) {
    return static_cast<const SetpointSchedule*>(c)->code_at(static_cast<std::int64_t>(at_us) * 1000);
  };
  const host::ScopedHostBoard scope(board);

  RunResult result;
  const std::int64_t h_ns = static_cast<std::int64_t>(plant.period_us) * 1000;
  const auto periods = static_cast<std::int64_t>(std::floor(sc.duration_s * 1e9 / static_cast<double>(h_ns)));
  const std::int64_t end_ns = periods * h_ns;
  std::size_t next_change = 1;
  const std::int64_t trace_ns = static_cast<std::int64_t>(opt.trace_step_us) * 1000;
  std::int64_t next_trace = 0;

  const auto record_trace = [&]() {
    TracePoint p;
    p.t_s = static_cast<double>(emu.now_ns()) * 1e-9;
    for (std::size_t i = 0; i < N; ++i) p.x.push_back(emu.state()[i]);
    p.setpoint_volts = emu.setpoint()[0];
    p.u_volts = emu.commanded_input(0);
    result.trace.push_back(std::move(p));
  };
  // Advance to t, applying set-point changes and recording the dense trace on the way.
  const auto advance = [&](std::int64_t t) {
    for (;;) {
      std::int64_t stop = t;
      const bool change = next_change < schedule.at_ns.size() && schedule.at_ns[next_change] <= stop;
      if (change) stop = schedule.at_ns[next_change];
      const bool trace = trace_ns > 0 && next_trace <= stop;
      if (trace) stop = next_trace;
      emu.advance_to(stop);
      if (trace && stop == next_trace) {
        record_trace();
        next_trace += trace_ns;
        continue;
      }
      if (change && stop == schedule.at_ns[next_change]) {
        emu.set_setpoint(setpoint_at(stop));
        ++next_change;
        continue;
      }
      if (stop == t) return;
    }
  };
  const auto apply_writes = [&]() {
    for (const host::PwmWrite& w : board.pwm_writes) emu.set_duty(w.channel, w.code);
    board.pwm_writes.clear();
  };
  const double r_sigma = std::sqrt(plant.measurement_covariance(0, 0));

  for (std::int64_t k = 0; k < periods; ++k) {
    const std::int64_t t_k = k * h_ns;
    if (kModel == app::TaskModel::kOneShot && k > 0) {
      advance(t_k);
      board.now_us = static_cast<std::uint32_t>(t_k / 1000);
      driver.actuation(board);
      apply_writes();
    }
    const JobTiming timing = jitter.draw(jitter_rng, static_cast<std::size_t>(k));
    const std::int64_t t_s = t_k + static_cast<std::int64_t>(timing.release_us) * 1000;
    advance(t_s);
    for (std::size_t o = 0; o < P; ++o) {
      const double noise = r_sigma * measurement_rng.normal();
      board.adc_codes[o] = emu.adc_code(o, noise);
    }
    board.now_us = static_cast<std::uint32_t>(t_s / 1000);
    board.next_actuation_us = static_cast<std::uint32_t>((t_k + h_ns) / 1000);
    const JobReport<N> report = driver.job(board);
    if (opt.record_jobs) {
      JobRecord r;
      r.t_sample_s = static_cast<double>(t_s) * 1e-9;
      r.tau_us = report.tau_us;
      r.y_volts = code_volts(board.adc_codes[0]);
      for (std::size_t i = 0; i < N; ++i) {
        r.x_true.push_back(emu.state()[i]);
        r.estimate.push_back(report.estimate[i]);
      }
      r.gain0 = report.gain0;
      const std::int64_t t_apply = kModel == app::TaskModel::kOneShot ? t_k + h_ns : t_s;
      r.setpoint_code = schedule.code_at(t_apply);
      r.setpoint_volts = code_volts(r.setpoint_code);
      r.y_code = board.adc_codes[0];
      r.t_apply_s = static_cast<double>(kModel == app::TaskModel::kOneShot ? t_apply : t_s + timing.exec_us * 1000LL) * 1e-9;
      r.u_volts = report.u_applied;
      result.job_records.push_back(std::move(r));
    }
    if (kModel == app::TaskModel::kStandard) {
      advance(t_s + static_cast<std::int64_t>(timing.exec_us) * 1000);
      apply_writes();
    }
  }
  advance(end_ns);
  result.cost = emu.cost();
  result.duration_s = static_cast<double>(end_ns) * 1e-9;
  result.jobs = driver.statistics().jobs;
  result.overruns = driver.statistics().overruns;
  result.faults = driver.statistics().faults;
  result.saturated = driver.saturated();
  return result;
}

template <typename T>
struct Tag {
  using type = T;
};
template <app::TaskModel kModel>
using ModelTag = std::integral_constant<app::TaskModel, kModel>;

/// Builds the estimator the options ask for and calls
/// f(Tag<Structure>, ModelTag<task model>, design, estimator) while the discretizers live.
template <typename Structure, typename Storage, typename Design, typename Model, typename F>
decltype(auto) with_estimator(const RunOptions& opt, const Design& design, const TableView<Storage>& view,
                              const Model& model, F&& f) {
  using Fmt = typename Design::Format;
  using app::TaskModel;
  constexpr std::size_t kN = Design::kStates;
  constexpr std::size_t kM = Design::kInputs;
  const TableDiscretizer<Fmt, Structure, Storage> table(view);
  const TableDiscretizer<Fmt, Structure, Storage, OutOfRange::kExtend, SubGrid::kNearest> nearest(view);
  const GenericDiscretizer<Fmt, kN, kM> generic(model);
  const Tag<Structure> tag;
  // The one-shot filters over the chosen discretizer.
  const auto one_shot = [&](const auto& disc) {
    using Disc = std::decay_t<decltype(disc)>;
    if (info(opt.approach).estimator == EstimatorKind::kHalfKalman) {
      return f(tag, ModelTag<TaskModel::kOneShot>{}, design, HalfKalman<Fmt, Structure, Disc>(design, disc, opt.noise));
    }
    return f(tag, ModelTag<TaskModel::kOneShot>{}, design, CompleteKalman<Fmt, Structure, Disc>(design, disc, opt.noise));
  };
  switch (info(opt.approach).estimator) {
    case EstimatorKind::kStandardKalman:
      return f(tag, ModelTag<TaskModel::kStandard>{}, design, StandardKalman<Fmt, Structure>(design, opt.noise));
    case EstimatorKind::kDeadbeat:
      return f(tag, ModelTag<TaskModel::kStandard>{}, design, DeadbeatObserver<Fmt, Structure>(design));
    case EstimatorKind::kHalfKalman:
    case EstimatorKind::kCompleteKalman:
      if (opt.discretizer == DiscretizerKind::kTable) return one_shot(table);
      if (opt.discretizer == DiscretizerKind::kNearest) return one_shot(nearest);
      return one_shot(generic);
  }
  throw std::logic_error("unknown estimator");
}

/// Dispatches on the context (generated header or run-time plant) and the number format.
template <typename F>
decltype(auto) with_controller_parts(const SimContext& ctx, const RunOptions& opt, F&& f) {
  if (ctx.generated()) {
    if (opt.format == NumberFormat::kFloat) {
      using K = generated::PlantConstants<float>;
      return with_estimator<generated::PlantStructure>(opt, K::kDesign, K::kTable, K::kModel, f);
    }
    if (opt.format == NumberFormat::kFixed) {
#if ONESHOT_GENERATED_FIXED_POINT
      using K = generated::PlantConstants<generated::FixedTag>;
      return with_estimator<generated::PlantStructure>(opt, K::kDesign, K::kTable, K::kModel, f);
#else
      throw std::invalid_argument(std::string("no fixed-point build for this plant: ") + generated::kFixedPointUnavailable);
#endif
    }
    using K = generated::PlantConstants<double>;
    return with_estimator<generated::PlantStructure>(opt, K::kDesign, K::kTable, K::kModel, f);
  }
  if (opt.format == NumberFormat::kFixed) {
    throw std::invalid_argument(
        "--number-format fixed needs the plant's Q formats at build time: configure with -DONESHOT_PLANT=" +
        ctx.plant().source + " and run without --plant");
  }
  const auto& plant = ctx.plant();
  return design::with_dimensions(plant.n(), plant.m(), plant.p(), [&](auto n, auto m, auto p) {
    constexpr std::size_t kN = decltype(n)::value;
    constexpr std::size_t kM = decltype(m)::value;
    constexpr std::size_t kP = decltype(p)::value;
    if (opt.format == NumberFormat::kFloat) {
      const auto design = design::controller_design<float, kN, kM, kP>(plant, ctx.design());
      const auto model = design::continuous_model_per_us<float, kN, kM>(plant, ctx.design());
      return with_estimator<DenseStructure<kN, kM, kP>>(opt, design, ctx.table_float().view(), model, f);
    }
    const auto design = design::controller_design<double, kN, kM, kP>(plant, ctx.design());
    const auto model = design::continuous_model_per_us<double, kN, kM>(plant, ctx.design());
    return with_estimator<DenseStructure<kN, kM, kP>>(opt, design, ctx.table_double().view(), model, f);
  });
}

/// simulate() with the job in the emulated MCU.
RunResult simulate_pil(const SimContext& ctx, const Scenario& scenario, std::uint64_t seed, const RunOptions& opt) {
  if (!ctx.generated()) {
    throw std::invalid_argument("PIL runs the firmware built for the compiled-in plant: run without --plant "
                                "(or configure the build with -DONESHOT_PLANT=FILE)");
  }
  const FirmwareInfo& fw = opt.pil->info();
  if (fw.format != to_string(opt.format)) {
    throw std::invalid_argument("the firmware image is " + fw.format + ", the run asks for " + to_string(opt.format));
  }
  if (fw.discretizer != to_string(opt.discretizer)) {
    throw std::invalid_argument("the firmware image uses the " + fw.discretizer + " discretizer, the run asks for " +
                                to_string(opt.discretizer));
  }
  using S = generated::PlantStructure;
  if (fw.n != static_cast<int>(S::kStates) || fw.m != static_cast<int>(S::kInputs) || fw.p != static_cast<int>(S::kOutputs)) {
    throw std::invalid_argument("the firmware image was built for another plant (dimensions differ)");
  }
  const auto run = [&](auto fmt_tag) {
    using Fmt = typename decltype(fmt_tag)::type;
    constexpr std::size_t kN = S::kStates;
    constexpr std::size_t kM = S::kInputs;
    constexpr std::size_t kP = S::kOutputs;
    if (info(opt.approach).model == app::TaskModel::kOneShot) {
      RemoteDriver<Fmt, kN, kM, kP, app::TaskModel::kOneShot> d(*opt.pil, opt.approach, opt.noise);
      return run_loop<kN, kM, kP, app::TaskModel::kOneShot>(ctx, scenario, seed, opt, d);
    }
    RemoteDriver<Fmt, kN, kM, kP, app::TaskModel::kStandard> d(*opt.pil, opt.approach, opt.noise);
    return run_loop<kN, kM, kP, app::TaskModel::kStandard>(ctx, scenario, seed, opt, d);
  };
  if (opt.format == NumberFormat::kFloat) return run(Tag<generated::PlantConstants<float>::Format>{});
#if ONESHOT_GENERATED_FIXED_POINT
  if (opt.format == NumberFormat::kFixed) return run(Tag<generated::FixedFormat>{});
#endif
  throw std::invalid_argument(std::string("no firmware number format ") + to_string(opt.format));
}

}  // namespace

bool approach_available(const SimContext& ctx, Approach a) { return a != Approach::kE || ctx.design().deadbeat; }

RunResult simulate(const SimContext& ctx, const Scenario& scenario, std::uint64_t seed, const RunOptions& options) {
  validate_scenario(scenario, ctx.plant());
  if (!approach_available(ctx, options.approach)) {
    throw std::invalid_argument(std::string("approach ") + info(options.approach).letter +
                                " is unavailable for this plant: " + ctx.design().deadbeat_unavailable_reason);
  }
  if (options.pil != nullptr) return simulate_pil(ctx, scenario, seed, options);
  return with_controller_parts(ctx, options, [&](auto structure, auto model, const auto& design, const auto& estimator) {
    using Design = std::decay_t<decltype(design)>;
    using Ctrl = Controller<typename Design::Format, typename decltype(structure)::type, std::decay_t<decltype(estimator)>>;
    Ctrl ctrl(design, estimator);
    LocalDriver<Ctrl, decltype(model)::value> driver(ctrl);
    return run_loop<Design::kStates, Design::kInputs, Design::kOutputs, decltype(model)::value>(ctx, scenario, seed,
                                                                                             options, driver);
  });
}

void with_job_replay(const SimContext& ctx, const RunOptions& options, const std::vector<JobRecord>& jobs,
                     const std::function<void(const std::function<void()>&)>& use) {
  with_controller_parts(ctx, options, [&](auto structure, auto, const auto& design, const auto& estimator) {
    using Design = std::decay_t<decltype(design)>;
    using Ctrl = Controller<typename Design::Format, typename decltype(structure)::type, std::decay_t<decltype(estimator)>>;
    using St = typename Design::Format::State;
    constexpr std::size_t kP = Design::kOutputs;
    Ctrl ctrl(design, estimator);
    const auto initial = ctrl;
    // Inputs converted once, as the ADC driver would hand them over.
    std::vector<typename Ctrl::OutputVec> ys(jobs.size());
    std::vector<typename Ctrl::OutputVec> rs(jobs.size());
    for (std::size_t k = 0; k < jobs.size(); ++k)
      for (std::size_t o = 0; o < kP; ++o) {
        ys[k][o] = output_of_code(design.sensor, o, jobs[k].y_code);
        rs[k][o] = output_of_code(design.sensor, o, jobs[k].setpoint_code);
      }
    std::int32_t codes[Design::kInputs] = {};
    St sink{};
    use([&]() {
      ctrl = initial;
      for (std::size_t k = 0; k < jobs.size(); ++k) ctrl.job(jobs[k].tau_us, ys[k], rs[k], codes);
      sink = ctrl.estimator().prediction()[0];
    });
    static_cast<void>(sink);
  });
}

}  // namespace oneshot::sim
