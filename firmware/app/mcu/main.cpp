/// @file main.cpp
/// @brief The oneshot firmware: the control task of every approach behind the PIL link.
///
/// Built once per (target, number format, discretizer). The harness selects the approach
/// with kConfig, sends each sampling instant as kSample (the job runs between the two
/// instruction-count markers) and each actuation instant as kTick, which raises the SoC's
/// timer interrupt: its handler is the task's actuation interrupt.
#include <cstddef>
#include <cstdint>

#include "oneshot/app/control_task.hpp"
#include "oneshot/app/pil_protocol.hpp"
#include "oneshot/app/wait_until_set.hpp"
#include "oneshot/complete_kalman.hpp"
#include "oneshot/controller.hpp"
#include "oneshot/deadbeat_observer.hpp"
#include "oneshot/fixed_point.hpp"
#include "oneshot/generated/plant_tables.hpp"
#include "oneshot/generic_discretizer.hpp"
#include "oneshot/half_kalman.hpp"
#include "oneshot/mcu/pil_board.hpp"
#include "oneshot/standard_kalman.hpp"
#include "oneshot/table_discretizer.hpp"
#include "oneshot_job.h"  // the generated C99 job (lut_gen --c-job-dir), approaches 5 and 6
#include "c_job_loop.hpp"
#include "pil_link.hpp"

namespace oneshot::mcu {
PilRegisters g_pil;
}  // namespace oneshot::mcu

namespace {

using namespace oneshot;
namespace pil = app::pil;
using app::TaskModel;
using mcu::PilBoard;
using mcu::g_pil;
using mcu::PilLink;
namespace soc = mcu::soc;

#if ONESHOT_FW_FIXED
#if !ONESHOT_GENERATED_FIXED_POINT
#error "this plant has no fixed-point build (see kFixedPointUnavailable in the generated header)"
#endif
using Tag = generated::FixedTag;
constexpr std::uint8_t kFormatId = 1;
#else
using Tag = float;
constexpr std::uint8_t kFormatId = 0;
#endif
using K = generated::PlantConstants<Tag>;
using Fmt = K::Format;
using Structure = generated::PlantStructure;
constexpr std::size_t kN = Structure::kStates;
constexpr std::size_t kM = Structure::kInputs;
constexpr std::size_t kP = Structure::kOutputs;
static_assert(kP <= mcu::kMaxChannels && kM <= mcu::kMaxChannels, "too many channels for the PIL link");

template <typename View>
struct StorageOf;
template <typename S, typename SlotId>
struct StorageOf<TableView<S, SlotId>> {
  using type = S;
};

// ONESHOT_FW_DISC: 0 table (exact between grid points), 1 generic, 2 table at the nearest grid point.
using Storage = StorageOf<std::remove_cv_t<decltype(K::kTable)>>::type;
#if ONESHOT_FW_DISC == 1
using Disc = GenericDiscretizer<Fmt, kN, kM>;
const Disc g_disc(K::kModel);
#elif ONESHOT_FW_DISC == 2
using Disc = TableDiscretizer<Fmt, Structure, Storage, OutOfRange::kExtend, SubGrid::kNearest>;
const Disc g_disc(K::kTable);
#else
using Disc = TableDiscretizer<Fmt, Structure, Storage>;
const Disc g_disc(K::kTable);
#endif
constexpr std::uint8_t kDiscId = ONESHOT_FW_DISC;

/// Raw 32-bit image of a scalar: IEEE bits, or the sign-extended fixed mantissa.
template <typename T>
std::uint32_t raw32(T v) {
  if constexpr (kIsFloating<T>) {
    static_assert(sizeof(T) == 4, "the firmware reports single precision");
    std::uint32_t u = 0;
    __builtin_memcpy(&u, &v, 4);
    return u;
  } else {
    return static_cast<std::uint32_t>(static_cast<std::int32_t>(v.raw()));
  }
}

template <typename T, typename = void>
struct HasGain : std::false_type {};
template <typename T>
struct HasGain<T, std::void_t<decltype(std::declval<const T&>().gain())>> : std::true_type {};

/// One approach: its controller and task.
template <typename Est, TaskModel kModel>
struct Loop {
  using Ctrl = Controller<Fmt, Structure, Est>;
  Ctrl ctrl;
  app::ControlTask<PilBoard, Ctrl, kModel> task{ctrl};

  explicit Loop(const Est& e) : ctrl(K::kDesign, e) {}

  void configure(const Est& e, const std::int32_t (&codes)[kM]) {
    ctrl = Ctrl(K::kDesign, e);
    typename Ctrl::InputVec u0;
    for (std::size_t j = 0; j < kM; ++j) u0[j] = input_of_code(K::kDesign.actuator, j, codes[j]);
    ctrl.estimator().reset(typename Ctrl::StateVec{}, K::kDesign.p0, u0);
    task.reset();
  }
  void results(pil::Writer& w) const {
    for (std::size_t j = 0; j < kM; ++j) w.u(raw32(ctrl.applied_input()[j]), 4);
    for (std::size_t i = 0; i < kN; ++i) w.u(raw32(ctrl.estimator().prediction()[i]), 4);
    if constexpr (HasGain<Est>::value) {
      w.u(raw32(ctrl.estimator().gain()[0]), 4);
    } else {
      w.u(0, 4);
    }
  }
};

// The generated C99 jobs, named by the image's build (cmake/oneshot_firmware.cmake): approach 5
// is the job of this image's format and sub-grid policy, ONESHOT_CJOB_MAIN_VARIANT (B's job
// behind the same task interface, for instruction counts and the comparison with the C++ job
// on the MCU); approach 6 its own-arithmetic twin, ONESHOT_CJOB_OWN_ARITH_VARIANT (q15 in
// fixed-point images; float_poly, Φ, Γ, Q_d as one polynomial in τ per entry, in float table
// images), whose oracle is the same C compiled on the host. Each *_HAS names the generated
// header's ONESHOT_JOB_HAS_<VARIANT>: 0 when the plant lacks that variant.
#define ONESHOT_CJOB_CAT2(a, b) a##b
#define ONESHOT_CJOB_CAT(a, b) ONESHOT_CJOB_CAT2(a, b)
#define ONESHOT_CJOB_FN(variant, name) ONESHOT_CJOB_CAT(ONESHOT_CJOB_CAT(oneshot_job_, variant), name)
#define ONESHOT_CJOB_TRAITS(Name, variant)                                                       \
  struct Name {                                                                                  \
    using State = ONESHOT_CJOB_FN(variant, _t);                                                  \
    static constexpr bool kFixed = ONESHOT_FW_FIXED;                                             \
    static void init(State* s, std::uint16_t code) { ONESHOT_CJOB_FN(variant, _init)(s, code); } \
    static std::uint16_t run(State* s, std::int32_t tau, std::uint16_t adc, std::uint16_t sp) {  \
      return ONESHOT_CJOB_FN(variant, _run)(s, tau, adc, sp);                                    \
    }                                                                                            \
  };
#if defined(ONESHOT_CJOB_MAIN_VARIANT) && ONESHOT_CJOB_MAIN_HAS
#define ONESHOT_CJOB 1
ONESHOT_CJOB_TRAITS(CJobMain, ONESHOT_CJOB_MAIN_VARIANT)
#endif
#if defined(ONESHOT_CJOB_OWN_ARITH_VARIANT) && ONESHOT_CJOB_OWN_ARITH_HAS
#define ONESHOT_CJOB_OWN_ARITH 1
ONESHOT_CJOB_TRAITS(CJobOwnArith, ONESHOT_CJOB_OWN_ARITH_VARIANT)
#endif
static_assert(kM == 1 && kP == 1, "the C job adapter serves one input and one output");
#ifdef ONESHOT_CJOB
mcu::CJobLoop<CJobMain, PilBoard, kN> g_cjob;
#endif
#ifdef ONESHOT_CJOB_OWN_ARITH
mcu::CJobLoop<CJobOwnArith, PilBoard, kN> g_cjob_own_arith;
#endif

using HalfEst = HalfKalman<Fmt, Structure, Disc>;
using CompleteEst = CompleteKalman<Fmt, Structure, Disc>;
using StandardEst = StandardKalman<Fmt, Structure>;
using DeadbeatEst = DeadbeatObserver<Fmt, Structure>;

Loop<StandardEst, TaskModel::kStandard> g_standard{StandardEst(K::kDesign, NoiseModel::kExact)};
Loop<HalfEst, TaskModel::kOneShot> g_half{HalfEst(K::kDesign, g_disc, NoiseModel::kExact)};
Loop<CompleteEst, TaskModel::kOneShot> g_complete{CompleteEst(K::kDesign, g_disc, NoiseModel::kExact)};
Loop<DeadbeatEst, TaskModel::kStandard> g_deadbeat{DeadbeatEst(K::kDesign)};

/// Outcome of one job for the reply.
struct JobOutcome {
  Status status;
  std::int32_t tau_us;
};

/// Approach letters A–E as 0–4: A, D standard Kalman; B half; C complete; E deadbeat; 5: the
/// generated C99 job (B's job, table images only); 6: its own-arithmetic twin (q15 in fixed images,
/// float_poly in float table images).
std::uint8_t g_approach = 1;
volatile bool g_tick_done = false;

/// This image as its kHello reply states it.
constexpr pil::ImageInfo kImage{soc::kPilTargetId, kFormatId, kDiscId, kN, kM, kP};

template <typename F>
decltype(auto) with_loop(F&& f) {
  switch (g_approach) {
    case 1: return f(g_half);
    case 2: return f(g_complete);
    case 4: return f(g_deadbeat);
#ifdef ONESHOT_CJOB
    case 5: return f(g_cjob);
#endif
#ifdef ONESHOT_CJOB_OWN_ARITH
    case 6: return f(g_cjob_own_arith);
#endif
    default: return f(g_standard);
  }
}

void write_pwm(pil::Writer& w) {
  w.u(static_cast<std::uint32_t>(g_pil.writes), 1);
  for (std::size_t i = 0; i < g_pil.writes; ++i) {
    w.u(g_pil.write_channel[i], 1);
    w.u(static_cast<std::uint32_t>(g_pil.write_code[i]), 2);
  }
}

/// Waits for the actuation interrupt without sleeping through it: the flag is tested with
/// interrupts masked, and WFI still wakes on the pending interrupt, which runs as soon as
/// they are unmasked (a test then a WFI with interrupts on could miss the wake-up).
void wait_for_tick() {
  app::wait_until_set<mcu::Cpu>(g_tick_done);
}

/// This image's requests (PilRuntime answers kHello, kCalibrate and kEcho); `r` is begun.
void handle(const pil::Frame& q, pil::Frame& r) {
  using pil::malformed;
  pil::Writer w(r);
  switch (q.type) {
    case pil::Type::kConfig: {
      pil::ConfigRequest<kM> c;
      if (!pil::decode(q, c)) return malformed(r);
#ifndef ONESHOT_CJOB
      if (c.approach == pil::kCJobApproach) return malformed(r);  // no generated C job in this image
#endif
#ifndef ONESHOT_CJOB_OWN_ARITH
      if (c.approach == pil::kCJobOwnArithApproach) return malformed(r);  // no own-arithmetic twin in this image
#endif
      const NoiseModel noise = c.exact_noise ? NoiseModel::kExact : NoiseModel::kConstant;
      g_approach = c.approach;
      g_half.configure(HalfEst(K::kDesign, g_disc, noise), c.codes);
      g_complete.configure(CompleteEst(K::kDesign, g_disc, noise), c.codes);
      g_standard.configure(StandardEst(K::kDesign, noise), c.codes);
      g_deadbeat.configure(DeadbeatEst(K::kDesign), c.codes);
#ifdef ONESHOT_CJOB
      g_cjob.configure(c.codes);
#endif
#ifdef ONESHOT_CJOB_OWN_ARITH
      g_cjob_own_arith.configure(c.codes);
#endif
      clear_saturation_flag();
      w.u(g_approach, 1);
      return;
    }
    case pil::Type::kSample: {
      pil::SampleRequest<kP> sample;
      if (!pil::decode(q, sample)) return malformed(r);
      g_pil.now_us = sample.now_us;
      g_pil.next_actuation_us = sample.next_actuation_us;
      for (std::size_t o = 0; o < kP; ++o) g_pil.adc[o] = sample.adc[o];
      for (std::size_t o = 0; o < kP; ++o) g_pil.setpoint[o] = sample.setpoint[o];
      g_pil.writes = 0;
      const JobOutcome job = with_loop([](auto& loop) {
        oneshot_job_begin();
        const Status s = loop.task.run_job();
        oneshot_job_end();
        return JobOutcome{s, loop.task.statistics().last_tau_us};
      });
      w.u(static_cast<std::uint8_t>(job.status), 1);
      w.s(job.tau_us, 4);
      w.u(saturation_flag() ? 1U : 0U, 1);
      write_pwm(w);
      with_loop([&](auto& loop) { loop.results(w); });
      return;
    }
    case pil::Type::kTick: {
      pil::TickRequest tick;
      if (!pil::decode(q, tick)) return malformed(r);
      g_pil.now_us = tick.now_us;
      g_pil.writes = 0;
      g_tick_done = false;
      soc::ActuationTimer::arm_once();
      wait_for_tick();
      write_pwm(w);
      return;
    }
    default:
      pil::write_fault(r, pil::kFaultUnknownRequest);
      return;
  }
}

}  // namespace

/// The actuation timer interrupt: the task's one-shot actuation.
extern "C" void oneshot_actuation_timer_handler() {
  soc::ActuationTimer::acknowledge();
  with_loop([](auto& loop) { loop.task.on_actuation_interrupt(); });
  g_tick_done = true;
}

int main() {
  PilLink::init();
  soc::ActuationTimer::init();
  mcu::interrupts_on();
  PilLink::serve(kImage, handle);
}
