/// @file freestanding_check.cpp
/// @brief Compiles every core template with -ffreestanding -fno-exceptions -fno-rtti.
///
/// Instantiates the whole control job (half, complete, standard, deadbeat; table and
/// generic; float and double) against the generated plant constants. Only core and
/// freestanding headers may be reachable from here.
#include "oneshot/complete_kalman.hpp"
#include "oneshot/controller.hpp"
#include "oneshot/deadbeat_observer.hpp"
#include "oneshot/generated/plant_tables.hpp"
#include "oneshot/generic_discretizer.hpp"
#include "oneshot/half_kalman.hpp"
#include "oneshot/standard_kalman.hpp"
#include "oneshot/table_discretizer.hpp"
#include "oneshot/time_us.hpp"
#include "oneshot/dimension_limits.hpp"

namespace {

using oneshot::generated::PlantConstants;
using oneshot::generated::PlantStructure;

template <typename View>
struct StorageOf;
template <typename Storage>
struct StorageOf<oneshot::TableView<Storage>> {
  using type = Storage;
};

template <typename S>
int run_all(std::int32_t tau_us, std::int32_t adc_code) {
  using K = PlantConstants<S>;
  using Fmt = typename K::Format;
  using Storage = std::remove_cv_t<std::remove_reference_t<decltype(K::kTable)>>;
  using Table = oneshot::TableDiscretizer<Fmt, PlantStructure, typename StorageOf<Storage>::type>;
  using Generic = oneshot::GenericDiscretizer<Fmt, PlantStructure::kStates, PlantStructure::kInputs>;
  const Table table(K::kTable);
  const Generic generic(K::kModel);
  oneshot::Vector<typename Fmt::State, 1> y;
  y[0] = oneshot::output_of_code(K::kDesign.sensor, 0, adc_code);
  const oneshot::Vector<typename Fmt::State, 1> r{};
  std::int32_t codes[1] = {0};
  int sum = 0;
  {
    using Est = oneshot::HalfKalman<Fmt, PlantStructure, Table>;
    oneshot::Controller<Fmt, PlantStructure, Est> c(K::kDesign, Est(K::kDesign, table, oneshot::NoiseModel::kExact));
    sum += static_cast<int>(c.job(tau_us, y, r, codes)) + codes[0];
  }
  {
    using Est = oneshot::CompleteKalman<Fmt, PlantStructure, Generic, oneshot::CovarianceUpdate::kJoseph>;
    oneshot::Controller<Fmt, PlantStructure, Est> c(K::kDesign, Est(K::kDesign, generic, oneshot::NoiseModel::kConstant));
    sum += static_cast<int>(c.job(tau_us, y, r, codes)) + codes[0];
  }
  {
    using Est = oneshot::StandardKalman<Fmt, PlantStructure>;
    oneshot::Controller<Fmt, PlantStructure, Est> c(K::kDesign, Est(K::kDesign, oneshot::NoiseModel::kExact));
    sum += static_cast<int>(c.job(tau_us, y, r, codes)) + codes[0];
  }
  {
    using Est = oneshot::DeadbeatObserver<Fmt, PlantStructure>;
    oneshot::Controller<Fmt, PlantStructure, Est> c(K::kDesign, Est(K::kDesign));
    sum += static_cast<int>(c.job(tau_us, y, r, codes)) + codes[0];
  }
  return sum;
}

}  // namespace

/// Entry point kept so the instantiations are not discarded.
int oneshot_freestanding_check(std::int32_t tau_us, std::int32_t adc_code) {
  return run_all<float>(tau_us, adc_code) + run_all<double>(tau_us, adc_code)
#if ONESHOT_GENERATED_FIXED_POINT
         + run_all<oneshot::generated::FixedTag>(tau_us, adc_code)
#endif
      ;
}
