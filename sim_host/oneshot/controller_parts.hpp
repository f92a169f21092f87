/// @file controller_parts.hpp
/// @brief The estimator of a run's options over a design (the dispatch every closed-loop run
///        of study 000 shares: the emulated board in simulation.cpp, the linear board).
#pragma once

#include <stdexcept>
#include <type_traits>

#include "oneshot/app/control_task.hpp"
#include "oneshot/complete_kalman.hpp"
#include "oneshot/deadbeat_observer.hpp"
#include "oneshot/generic_discretizer.hpp"
#include "oneshot/half_kalman.hpp"
#include "oneshot/standard_kalman.hpp"
#include "oneshot/table_discretizer.hpp"
#include "oneshot/table_view.hpp"
#include "simulation.hpp"

namespace oneshot::sim {

/// A type carried as a value.
template <typename T>
struct Tag {
  using type = T;  ///< The type.
};
/// A task model carried as a type.
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

}  // namespace oneshot::sim
