/// @file controller_dispatch.hpp
/// @brief The controller parts of a run (design, estimator, model) for the compiled-in plant or
///        a run-time plant in one number format: the dispatch the core runs of study 000 share
///        (simulation.cpp, simulation_runtime_*.cpp). Split by plant and format
///        so each source instantiates a part of the dimension x format x estimator product.
#pragma once

#include <stdexcept>
#include <string>
#include <type_traits>

#include "controller_parts.hpp"
#include "oneshot/design/dimension_dispatch.hpp"
#include "oneshot/design/fixed_size.hpp"
#include "oneshot/generated/plant_tables.hpp"
#include "oneshot/plant_structure.hpp"
#include "simulation.hpp"

namespace oneshot::sim {

/// Refuses the formats the C++ core does not run (q15, float_poly are the generated C job).
inline void require_core_format(const RunOptions& opt) {
  if (opt.format == NumberFormat::kQ15 || opt.format == NumberFormat::kFloatPoly) {
    throw std::invalid_argument(std::string("--number-format ") + to_string(opt.format) +
                                " is the generated C job: closed-loop runs only (not the C++ core)");
  }
}

/// Calls f(Tag<Structure>, ModelTag, design, estimator) with the compiled-in plant's constants in
/// the run's number format (float, fixed when the build has the plant's Q formats, double).
template <typename F>
decltype(auto) with_generated_parts(const RunOptions& opt, F&& f) {
  require_core_format(opt);
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

/// Calls f(Tag<Structure>, ModelTag, design, estimator) with the run-time plant of the context
/// (dense structure, dimensions dispatched) in Scalar (float or double).
template <typename Scalar, typename F>
decltype(auto) with_runtime_parts(const SimContext& ctx, const RunOptions& opt, F&& f) {
  static_assert(std::is_same_v<Scalar, float> || std::is_same_v<Scalar, double>, "run-time plants run in float or double");
  const auto& plant = ctx.plant();
  return design::with_dimensions(plant.n(), plant.m(), plant.p(), [&](auto n, auto m, auto p) {
    constexpr std::size_t kN = decltype(n)::value;
    constexpr std::size_t kM = decltype(m)::value;
    constexpr std::size_t kP = decltype(p)::value;
    const auto design = design::controller_design<Scalar, kN, kM, kP>(plant, ctx.design());
    const auto model = design::continuous_model_per_us<Scalar, kN, kM>(plant, ctx.design());
    if constexpr (std::is_same_v<Scalar, float>) {
      return with_estimator<DenseStructure<kN, kM, kP>>(opt, design, ctx.table_float().view(), model, f);
    } else {
      return with_estimator<DenseStructure<kN, kM, kP>>(opt, design, ctx.table_double().view(), model, f);
    }
  });
}

/// Refuses the fixed-point format for a run-time plant (its Q formats are chosen at build time).
inline void require_runtime_format(const SimContext& ctx, const RunOptions& opt) {
  require_core_format(opt);
  if (opt.format == NumberFormat::kFixed) {
    throw std::invalid_argument(
        "--number-format fixed needs the plant's Q formats at build time: configure with -DONESHOT_PLANT=" +
        ctx.plant().source + " and run without --plant");
  }
}

/// The plant and format dispatch: on_generated() for the compiled-in plant, else (the formats a
/// run-time plant cannot run refused) on_float() or on_double().
template <typename G, typename F32, typename F64>
decltype(auto) dispatch_plant(const SimContext& ctx, const RunOptions& opt, G&& on_generated, F32&& on_float, F64&& on_double) {
  if (ctx.generated()) return on_generated();
  require_runtime_format(ctx, opt);
  if (opt.format == NumberFormat::kFloat) return on_float();
  return on_double();
}

}  // namespace oneshot::sim
