/// @file petc_test_support.hpp
/// @brief What the study-petc tests share: the default setup, built once.
#pragma once

#include "petc_sim.hpp"

namespace oneshot::sim::petc {

/// The study's setup with the default options, built once per test binary.
inline const PetcSetup& default_setup() {
  static const PetcSetup s = make_setup(PetcOptions{});
  return s;
}

}  // namespace oneshot::sim::petc
