/// @file c_job_reference.cpp
/// @brief Reference job sequences for the generated C job: the C++ core (approach B: half
///        Kalman, one-shot controller, table discretizer, exact Q_d) run on long random τ /
///        ADC / set-point sequences, every output written bit for bit.
///
/// Usage: c_job_reference OUT_FILE JOBS_PER_VARIANT [SEED]
/// Per variant the file holds "variant NAME JOBS PWM0", then one line per job:
///   tau_us adc_code setpoint_code | pwm status saturated x[0..n) k[0..n) u[0..m)
/// Fixed-point values are raw mantissas; float values are their IEEE bit patterns.
/// The sequence is closed loop on the reference plant (exact double model, process and
/// measurement noise, the τ of a jittered one-shot task), interleaved with stress jobs:
/// τ off the table's range (negative, beyond h and 4h, huge), exact grid points, garbage
/// ADC codes and extreme set-points, so that every branch (clamp, extension, saturation)
/// is exercised.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <random>
#include <string>

#include "oneshot/controller.hpp"
#include "oneshot/fixed_point.hpp"
#include "oneshot/generated/plant_tables.hpp"
#include "oneshot/generic_discretizer.hpp"
#include "oneshot/half_kalman.hpp"
#include "oneshot/table_discretizer.hpp"

namespace {

using namespace oneshot;
using Structure = generated::PlantStructure;
constexpr std::size_t kN = Structure::kStates;
constexpr std::size_t kM = Structure::kInputs;
static_assert(Structure::kOutputs == 1 && kM == 1, "the reference covers the single-input, single-output job");

template <typename View>
struct StorageOf;
template <typename S, typename SlotId>
struct StorageOf<TableView<S, SlotId>> {
  using type = S;
};

template <typename T>
long long raw_bits(T v) {
  if constexpr (kIsFloating<T>) {
    std::uint32_t u = 0;
    std::memcpy(&u, &v, sizeof u);
    return static_cast<long long>(u);
  } else {
    return static_cast<long long>(v.raw());
  }
}

/// The plant in double: Φ(t), Γ(t) from the generic routine.
struct Plant {
  using K = generated::PlantConstants<double>;
  GenericDiscretizer<UniformFormat<double>, kN, kM> gen{K::kModel};
  Vector<double, kN> x{};
  void advance(std::int32_t dt_us, double u) {
    Discretization<UniformFormat<double>, kN, kM> d;
    ONESHOT_ASSERT(is_exact(gen.discretize(dt_us, d, WithQd::kNo)));
    Vector<double, kN> next;
    for (std::size_t i = 0; i < kN; ++i) {
      next[i] = d.gamma(i, 0) * u;
      for (std::size_t k = 0; k < kN; ++k) next[i] += d.phi(i, k) * x[k];
    }
    x = next;
  }
};

template <typename Tag, SubGrid kSub>
void run_variant(std::FILE* out, const char* name, int jobs, std::uint64_t seed) {
  using K = generated::PlantConstants<Tag>;
  using Fmt = typename K::Format;
  using Storage = typename StorageOf<std::remove_cv_t<decltype(K::kTable)>>::type;
  using Disc = TableDiscretizer<Fmt, Structure, Storage, OutOfRange::kExtend, kSub>;
  using Est = HalfKalman<Fmt, Structure, Disc>;
  using Ctrl = Controller<Fmt, Structure, Est>;
  using KD = generated::PlantConstants<double>;
  const auto& design = KD::kDesign;
  const std::int32_t h = design.period_us;
  const std::int32_t g = K::kTable.granularity_us;
  const std::int32_t steps = design.actuator.steps;
  const Disc disc(K::kTable);
  Ctrl ctrl(K::kDesign, Est(K::kDesign, disc, NoiseModel::kExact));
  std::mt19937_64 rng(seed);
  const auto uniform = [&](double a, double b) { return a + (b - a) * (static_cast<double>(rng() >> 11) * 0x1p-53); };
  const auto integer = [&](std::int64_t a, std::int64_t b) {  // inclusive
    return a + static_cast<std::int64_t>(rng() % static_cast<std::uint64_t>(b - a + 1));
  };
  std::normal_distribution<double> normal(0.0, 1.0);
  const double lsb = design.sensor.volts_per_code[0];
  const double y0 = design.sensor.y_offset[0];
  const auto code_of = [&](double v) {
    const double c = std::round((v - y0) / lsb);
    return static_cast<std::int32_t>(std::min(4095.0, std::max(0.0, c)));
  };
  const std::int32_t pwm0 = static_cast<std::int32_t>(std::lround(-design.actuator.u_min[0] * design.actuator.steps_per_volt[0]));
  typename Ctrl::InputVec u0;
  u0[0] = input_of_code(K::kDesign.actuator, 0, pwm0);
  ctrl.estimator().reset(typename Ctrl::StateVec{}, K::kDesign.p0, u0);
  std::fprintf(out, "variant %s %d %d\n", name, jobs, pwm0);

  Plant plant;
  double u_volts = design.actuator.u_min[0] + pwm0 * design.actuator.volts_per_step[0];
  double setpoint = 0;
  const double rn = std::sqrt(design.r(0, 0));
  for (int k = 0; k < jobs; ++k) {
    if (k % 20 == 0) setpoint = uniform(-0.5, 0.5);
    // τ of a one-shot job released 0–20 ms after the previous actuation (B's regime), mostly;
    // otherwise anywhere in the table, on its grid, or outside it.
    std::int32_t tau = 0;
    const int kind = static_cast<int>(integer(0, 99));
    if (kind < 60) {
      tau = static_cast<std::int32_t>(integer(h - 20'000 - 600, h - 200));
    } else if (kind < 80) {
      tau = static_cast<std::int32_t>(integer(0, h));
    } else if (kind < 88) {
      tau = static_cast<std::int32_t>(integer(0, h / 500) * 500);  // grid points and midpoints
    } else if (kind < 92) {
      tau = static_cast<std::int32_t>(integer(-h, -1));
    } else if (kind < 96) {
      tau = static_cast<std::int32_t>(integer(h + 1, 6 * h));
    } else {
      tau = static_cast<std::int32_t>(integer(0, 1) != 0 ? integer(-100'000'000, 100'000'000) : integer(-5, 5));
    }
    // The C++ core's nearest policy leaves τ ≤ 0 unrounded and then asserts that h − τ is on
    // the grid: a negative τ is only valid there on the grid.
    if constexpr (kSub == SubGrid::kNearest) {
      if (tau < 0) tau = -static_cast<std::int32_t>(((-static_cast<std::int64_t>(tau)) / g) * g);
    }
    const std::int32_t physical = std::min(h, std::max<std::int32_t>(0, tau));
    plant.advance(h - physical, u_volts);
    for (std::size_t i = 0; i < kN; ++i) plant.x[i] += 1e-4 * normal(rng);
    std::int32_t adc = code_of(plant.x[0] + rn * normal(rng));
    std::int32_t sp = code_of(setpoint);
    if (integer(0, 99) < 3) adc = static_cast<std::int32_t>(integer(0, 4095));  // garbage samples
    if (integer(0, 199) == 0) sp = integer(0, 1) != 0 ? 4095 : 0;             // extreme set-points
    typename Ctrl::OutputVec y;
    typename Ctrl::OutputVec r;
    y[0] = output_of_code(K::kDesign.sensor, 0, adc);
    r[0] = output_of_code(K::kDesign.sensor, 0, sp);
    std::int32_t codes[kM] = {};
    clear_saturation_flag();
    const Status status = ctrl.job(tau, y, r, codes);
    const bool saturated = saturation_flag();
    std::fprintf(out, "%ld %d %d | %d %d %d", static_cast<long>(tau), adc, sp, codes[0], static_cast<int>(status),
                 saturated ? 1 : 0);
    for (std::size_t i = 0; i < kN; ++i) std::fprintf(out, " %lld", raw_bits(ctrl.estimator().prediction()[i]));
    for (std::size_t i = 0; i < kN; ++i) std::fprintf(out, " %lld", raw_bits(ctrl.estimator().gain()(i, 0)));
    std::fprintf(out, " %lld\n", raw_bits(ctrl.applied_input()[0]));
    plant.advance(physical, u_volts);
    u_volts = design.actuator.u_min[0] + codes[0] * design.actuator.volts_per_step[0];
    if (codes[0] < 0 || codes[0] > steps) std::fprintf(stderr, "c_job_reference: code out of range\n");
  }
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: c_job_reference OUT_FILE JOBS_PER_VARIANT [SEED]\n");
    return 2;
  }
  const int jobs = std::atoi(argv[2]);
  const std::uint64_t seed = argc > 3 ? std::strtoull(argv[3], nullptr, 10) : 16;
  if (jobs <= 0) {
    std::fprintf(stderr, "c_job_reference: JOBS_PER_VARIANT must be positive\n");
    return 2;
  }
  std::FILE* out = std::fopen(argv[1], "w");
  if (out == nullptr) {
    std::fprintf(stderr, "c_job_reference: cannot write %s\n", argv[1]);
    return 1;
  }
  std::fprintf(out, "oneshot-c-job-reference 1 n %zu\n", kN);
#if ONESHOT_GENERATED_FIXED_POINT
  run_variant<generated::FixedTag, SubGrid::kExact>(out, "fixed_table", jobs, seed);
  run_variant<generated::FixedTag, SubGrid::kNearest>(out, "fixed_nearest", jobs, seed + 1);
#endif
  run_variant<float, SubGrid::kExact>(out, "float_table", jobs, seed + 2);
  run_variant<float, SubGrid::kNearest>(out, "float_nearest", jobs, seed + 3);
  const bool ok = std::fclose(out) == 0;
  return ok ? 0 : 1;
}
