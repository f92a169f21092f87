/// @file size_probe.cpp
/// @brief Flash, RAM and stack of one control job for a synthetic dense n-state plant
///        (ONESHOT_PROBE_N states, one input, one output): the half Kalman filter, the
///        generic float discretizer (no table memory; Van Loan on 2n×2n), the control law.
///
/// No plant numbers are known at compile time (the design and the model are read through
/// volatile pointers), so nothing folds away: the image holds the whole job for that n.
/// Built per n by oneshot-<target>-size-probe-n<N> (not part of ALL); the README lists
/// the largest n whose image fits the Cortex-M0's flash and RAM with its stack bound.
#include <cstddef>
#include <cstdint>

#include "oneshot/controller.hpp"
#include "oneshot/generic_discretizer.hpp"
#include "oneshot/half_kalman.hpp"
#include "oneshot/number_format.hpp"
#include "oneshot/plant_structure.hpp"

#ifndef ONESHOT_PROBE_N
#error "define ONESHOT_PROBE_N"
#endif

namespace {

using namespace oneshot;
constexpr std::size_t kN = ONESHOT_PROBE_N;
using Fmt = UniformFormat<float>;
using Structure = DenseStructure<kN, 1, 1>;
using Disc = GenericDiscretizer<Fmt, kN, 1>;
using Est = HalfKalman<Fmt, Structure, Disc>;
using Ctrl = Controller<Fmt, Structure, Est>;

const ControllerDesign<Fmt, kN, 1, 1> kDesign{};
const typename Disc::Model kModel{};
// Read through volatile pointers: the compiler cannot assume the (zero) contents.
const ControllerDesign<Fmt, kN, 1, 1>* volatile g_design = &kDesign;
const typename Disc::Model* volatile g_model = &kModel;

}  // namespace


/// Inputs and outputs of the job loop (a debugger or a test harness would drive them).
volatile std::int32_t g_tau_us = 7000;
volatile float g_y = 0.0F;
volatile float g_r = 0.0F;
volatile std::int32_t g_code = 0;
volatile std::uint8_t g_status = 0;
volatile std::uint8_t g_noise_exact = 1;

int main() {
  const Disc disc(*g_model);  // locals: their RAM is in main's stack frame, counted by the bound
  Ctrl ctrl(*g_design, Est(*g_design, disc, g_noise_exact != 0U ? NoiseModel::kExact : NoiseModel::kConstant));
  for (;;) {
    Vector<float, 1> y;
    Vector<float, 1> r;
    y[0] = g_y;
    r[0] = g_r;
    std::int32_t codes[1] = {};
    g_status = static_cast<std::uint8_t>(ctrl.job(g_tau_us, y, r, codes));
    g_code = codes[0];
  }
}
