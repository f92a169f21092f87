/// @file study_model.hpp
/// @brief The send-on-delta study's model from its default plant file, loaded once for all the
///        study's tests.
#pragma once

#include "sod_model.hpp"

namespace oneshot::sod {

/// The model of the default plant file (default_sod_plant_path()), loaded on first use.
inline const SodModel& study_model() {
  static const SodModel m = load_sod_model(default_sod_plant_path());
  return m;
}

}  // namespace oneshot::sod
