/// @file study_plant.hpp
/// @brief The dropping study's default plant, loaded once for all the study's tests.
#pragma once

#include "dropping_plant.hpp"

namespace oneshot::dropping {

/// The study's default plant (load_dropping_plant("")), loaded on first use.
inline const DroppingPlant& study_plant() {
  static const DroppingPlant p = load_dropping_plant("");
  return p;
}

}  // namespace oneshot::dropping
