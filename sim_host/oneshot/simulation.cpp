/// @file simulation.cpp
/// @brief Closed-loop runs (see simulation.hpp).
#include "simulation.hpp"

#include "board_loop.hpp"
#include "c_job_driver.hpp"
#include "control_drivers.hpp"
#include "core_board_run.hpp"
#include "oneshot_job.h"  // the generated C99 job, compiled into this build (oneshot_c_job)

#include <cmath>
#include <cstring>
#include <functional>
#include <stdexcept>
#include <type_traits>

#include "oneshot/app/control_task.hpp"
#include "oneshot/controller.hpp"
#include "oneshot/fixed_point.hpp"
#include "oneshot/design/structure_analysis.hpp"
#include "oneshot/generated/plant_tables.hpp"
#include "oneshot/host/host_board.hpp"
#include "oneshot/plant_structure.hpp"
#include "oneshot/sim/pil_link.hpp"
#include "oneshot/util/enum_names.hpp"

namespace oneshot::sim {

namespace {

constexpr util::EnumName<NumberFormat> kNumberFormatNames[] = {
    {NumberFormat::kFloat, "float"}, {NumberFormat::kDouble, "double"}, {NumberFormat::kFixed, "fixed"},
    {NumberFormat::kQ15, "q15"},     {NumberFormat::kFloatPoly, "float_poly"}};
constexpr util::EnumName<DiscretizerKind> kDiscretizerNames[] = {
    {DiscretizerKind::kTable, "table"}, {DiscretizerKind::kNearest, "nearest"}, {DiscretizerKind::kGeneric, "generic"}};

}  // namespace

const char* to_string(NumberFormat f) { return util::enum_name(kNumberFormatNames, f); }
std::optional<NumberFormat> number_format_named(const std::string& name) { return util::enum_value(kNumberFormatNames, name); }
std::vector<std::string> number_format_names() { return util::enum_names(kNumberFormatNames); }

const char* to_string(DiscretizerKind d) { return util::enum_name(kDiscretizerNames, d); }
std::optional<DiscretizerKind> discretizer_named(const std::string& name) { return util::enum_value(kDiscretizerNames, name); }
std::vector<std::string> discretizer_names() { return util::enum_names(kDiscretizerNames); }

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
      return run_board_loop<kN, kM, kP, app::TaskModel::kOneShot>(ctx, scenario, seed, opt, d);
    }
    RemoteDriver<Fmt, kN, kM, kP, app::TaskModel::kStandard> d(*opt.pil, opt.approach, opt.noise);
    return run_board_loop<kN, kM, kP, app::TaskModel::kStandard>(ctx, scenario, seed, opt, d);
  };
  if (opt.format == NumberFormat::kFloat) return run(Tag<generated::PlantConstants<float>::Format>{});
#if ONESHOT_GENERATED_FIXED_POINT
  if (opt.format == NumberFormat::kFixed) return run(Tag<generated::FixedFormat>{});
#endif
  throw std::invalid_argument(std::string("no firmware number format ") + to_string(opt.format));
}

#if defined(ONESHOT_JOB_HAS_Q15_TABLE) && defined(ONESHOT_JOB_HAS_Q15_NEAREST) && ONESHOT_JOB_INPUTS == 1
#define ONESHOT_SIM_Q15_TRAITS(Name, prefix, up)                                                \
  struct Name {                                                                                 \
    using State = prefix##t;                                                                    \
    static constexpr bool kFixed = true;                                                        \
    static constexpr int kStateFrac = up##_STATE_FRAC_BITS;                                     \
    static constexpr int kGainFrac = up##_GAIN_FRAC_BITS;                                       \
    static constexpr int kInputFrac = up##_INPUT_FRAC_BITS;                                     \
    static void init(State* s, std::uint16_t code) { prefix##init(s, code); }                   \
    static std::uint16_t run(State* s, std::int32_t tau, std::uint16_t adc, std::uint16_t sp) { \
      return prefix##run(s, tau, adc, sp);                                                      \
    }                                                                                           \
  };
ONESHOT_SIM_Q15_TRAITS(Q15Table, oneshot_job_q15_table_, ONESHOT_JOB_Q15_TABLE)
ONESHOT_SIM_Q15_TRAITS(Q15Nearest, oneshot_job_q15_nearest_, ONESHOT_JOB_Q15_NEAREST)
#define ONESHOT_SIM_HAS_Q15 1
#endif

#if defined(ONESHOT_JOB_HAS_FLOAT_POLY) && ONESHOT_JOB_INPUTS == 1
/// The float_poly C job (IEEE single values: binary points 0).
struct FloatPolyJob {
  using State = oneshot_job_float_poly_t;
  static constexpr bool kFixed = false;
  static constexpr int kStateFrac = 0;
  static constexpr int kGainFrac = 0;
  static constexpr int kInputFrac = 0;
  static void init(State* s, std::uint16_t code) { oneshot_job_float_poly_init(s, code); }
  static std::uint16_t run(State* s, std::int32_t tau, std::uint16_t adc, std::uint16_t sp) {
    return oneshot_job_float_poly_run(s, tau, adc, sp);
  }
};
#define ONESHOT_SIM_HAS_FLOAT_POLY 1
#endif

/// simulate() of approach B as the generated float_poly C job (the code approach 6 of the float
/// table images runs).
RunResult simulate_float_poly(const SimContext& ctx, const Scenario& scenario, std::uint64_t seed, const RunOptions& opt) {
  if (!ctx.generated()) {
    throw std::invalid_argument("--number-format float_poly runs the generated C job of the compiled-in plant: run without --plant");
  }
  if (opt.noise != NoiseModel::kExact) throw std::invalid_argument("the float_poly C job predicts with the exact Q_d: --noise-model exact");
  if (opt.discretizer != DiscretizerKind::kTable) throw std::invalid_argument("the float_poly C job is exact in tau: --discretizer table");
#ifdef ONESHOT_SIM_HAS_FLOAT_POLY
  using S = generated::PlantStructure;
  CJobDriver<FloatPolyJob, S::kStates> d;
  return run_board_loop<S::kStates, 1, 1, app::TaskModel::kOneShot>(ctx, scenario, seed, opt, d);
#else
  static_cast<void>(scenario);
  static_cast<void>(seed);
  throw std::invalid_argument("this plant's generated C job has no float_poly variant");
#endif
}

/// simulate() of approach B as the generated q15 C job (the code the MCU images run).
RunResult simulate_q15(const SimContext& ctx, const Scenario& scenario, std::uint64_t seed, const RunOptions& opt) {
  if (!ctx.generated()) {
    throw std::invalid_argument("--number-format q15 runs the generated C job of the compiled-in plant: run without --plant");
  }
  if (opt.noise != NoiseModel::kExact) throw std::invalid_argument("the q15 C job predicts with the exact Q_d: --noise-model exact");
  if (opt.discretizer == DiscretizerKind::kGeneric) throw std::invalid_argument("the q15 C job uses the table: --discretizer table or nearest");
#ifdef ONESHOT_SIM_HAS_Q15
  using S = generated::PlantStructure;
  if (opt.discretizer == DiscretizerKind::kNearest) {
    CJobDriver<Q15Nearest, S::kStates> d;
    return run_board_loop<S::kStates, 1, 1, app::TaskModel::kOneShot>(ctx, scenario, seed, opt, d);
  }
  CJobDriver<Q15Table, S::kStates> d;
  return run_board_loop<S::kStates, 1, 1, app::TaskModel::kOneShot>(ctx, scenario, seed, opt, d);
#else
  static_cast<void>(scenario);
  static_cast<void>(seed);
  throw std::invalid_argument("this plant's generated C job has no q15 variant (single input, fixed-point design needed)");
#endif
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
  if (options.format == NumberFormat::kQ15 || options.format == NumberFormat::kFloatPoly) {
    // The q15 / float_poly C job is B's job; the other approaches run as the double oracle beside it.
    if (options.approach == Approach::kB) {
      return options.format == NumberFormat::kQ15 ? simulate_q15(ctx, scenario, seed, options)
                                                  : simulate_float_poly(ctx, scenario, seed, options);
    }
    RunOptions d = options;
    d.format = NumberFormat::kDouble;
    return simulate(ctx, scenario, seed, d);
  }
  // Run-time plants: one source per format (simulation_runtime_*.cpp).
  return dispatch_plant(
      ctx, options, [&] { return with_generated_parts(options, CoreBoardRun{ctx, scenario, seed, options}); },
      [&] { return simulate_runtime<float>(ctx, scenario, seed, options); },
      [&] { return simulate_runtime<double>(ctx, scenario, seed, options); });
}

void with_job_replay(const SimContext& ctx, const RunOptions& options, const std::vector<JobRecord>& jobs,
                     const std::function<void(const std::function<void()>&)>& use) {
  // Run-time plants: with their runs, one source per format (simulation_runtime_*.cpp).
  dispatch_plant(
      ctx, options, [&] { with_generated_parts(options, CoreJobReplay{jobs, use}); },
      [&] { replay_runtime<float>(ctx, options, jobs, use); }, [&] { replay_runtime<double>(ctx, options, jobs, use); });
}

}  // namespace oneshot::sim
