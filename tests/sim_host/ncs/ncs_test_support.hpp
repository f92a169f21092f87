/// @file ncs_test_support.hpp
/// @brief What the study-ncs tests share: the default context and a short one-scenario setup.
#pragma once

#include "ncs_model.hpp"

namespace oneshot::ncs {

/// The plant file's context, loaded once.
inline const Context& context() {
  static const auto ctx = Context::load("");
  return *ctx;
}

/// A square wave ±amplitude of period 1 s, legs U[0.5, d_ms] ms, noise scale s.
inline Scenario short_scenario(double amplitude, double d_ms, double s = 1, double duration = 3) {
  Scenario sc;
  sc.name = "test";
  sc.amplitude_volts = amplitude;
  sc.period_s = 1;
  sc.max_delay_ms = d_ms;
  sc.noise_scale = s;
  sc.duration_s = duration;
  return sc;
}

}  // namespace oneshot::ncs
