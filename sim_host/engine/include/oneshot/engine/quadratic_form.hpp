/// @file quadratic_form.hpp
/// @brief zᵀ G z, the cost term of every engine plant.
#pragma once

#include <cstddef>

#include "oneshot/matrix.hpp"

namespace oneshot::engine {

/// zᵀ G z, summed row by row (the order every plant's cost uses).
template <std::size_t K>
double quadratic_form(const Matrix<double, K, K>& g, const Vector<double, K>& z) {
  double q = 0;
  for (std::size_t i = 0; i < K; ++i) {
    double row = 0;
    for (std::size_t j = 0; j < K; ++j) row += g(i, j) * z[j];
    q += z[i] * row;
  }
  return q;
}

}  // namespace oneshot::engine
