/// @file float_grid.cpp
/// @brief composed_float_grid(): the core's float table discretizer at every grid point.
#include "c_job/float_grid.hpp"

#include <cstddef>
#include <cstdint>

#include "oneshot/design/controller_synthesis.hpp"
#include "oneshot/design/dimension_dispatch.hpp"
#include "oneshot/number_format.hpp"
#include "oneshot/plant_structure.hpp"
#include "oneshot/table_discretizer.hpp"

namespace oneshot::design::cjob {
namespace {

template <std::size_t N, std::size_t M>
std::vector<float> grid_of(const TableData<float>& t) {
  // Dense structure: structural zeros enter as exact 0·x terms and ones as exact 1·x, so the
  // sums equal the structured kernels' (which skip them) in every free entry.
  using Lut = TableDiscretizer<UniformFormat<float>, DenseStructure<N, M, 1>, float>;
  const Lut lut(t.template view<SlotIdFor<N, M>>());
  std::vector<float> out;
  bool shared = true;  // entries sharing a slot stay equal after composition
  for (std::int32_t tau = 0; tau <= t.range_us; tau += t.granularity_us) {
    typename Lut::Triple d{NoInit{}};
    if (lut.discretize(tau, d, WithQd::kYes) != Status::kOk) throw DesignError("C job: grid point outside the table");
    std::vector<float> slot(t.slots, 0.0F);
    std::vector<bool> seen(t.slots, false);
    const auto take = [&](std::int16_t s, float v) {
      if (s < 0) return;  // structural 0 / 1
      const auto k = static_cast<std::size_t>(s);
      if (seen[k] && slot[k] != v) shared = false;
      slot[k] = v;
      seen[k] = true;
    };
    for (std::size_t i = 0; i < N; ++i) {
      for (std::size_t j = 0; j < N; ++j) take(t.phi_slot[i * N + j], d.phi(i, j));
      for (std::size_t j = 0; j < M; ++j) take(t.gamma_slot[i * M + j], d.gamma(i, j));
      for (std::size_t j = i; j < N; ++j) take(t.qd_slot[i * N + j], d.qd(i, j));
    }
    out.insert(out.end(), slot.begin(), slot.end());
  }
  if (!shared) out.clear();
  return out;
}

}  // namespace

std::vector<float> composed_float_grid(const TableData<float>& table) {
  return with_dimensions(table.n, table.m, 1, [&](auto n, auto m, auto) {
    return grid_of<decltype(n)::value, decltype(m)::value>(table);
  });
}

}  // namespace oneshot::design::cjob
