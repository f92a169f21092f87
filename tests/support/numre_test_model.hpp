/// @file numre_test_model.hpp
/// @brief The small two-state NUMRE model the PETC node tests and the node-frame fuzzer
///        drive: a stable upper-triangular A, input and disturbance on state 1, y = x₀.
#pragma once

#include "oneshot/node/numre_estimator.hpp"

namespace oneshot::test {

/// x⁺ = A x + b u + b_w w, y = c x + v with A = [0.9 0.1; 0 0.8], b = [0; 0.1], b_w = [0; 1],
/// c = [1 0], W = 1e-4, V = 1e-3.
inline node::NumreModel<double, 2> small_numre_model() {
  node::NumreModel<double, 2> m{};
  m.a(0, 0) = 0.9;
  m.a(0, 1) = 0.1;
  m.a(1, 1) = 0.8;
  m.b[1] = 0.1;
  m.b_w[1] = 1;
  m.c[0] = 1;
  m.w = 1e-4;
  m.v = 1e-3;
  return m;
}

}  // namespace oneshot::test
