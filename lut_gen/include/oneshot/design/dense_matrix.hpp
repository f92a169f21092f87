/// @file dense_matrix.hpp
/// @brief Run-time sized matrix of doubles for plant descriptions and reports (host only).
#pragma once

#include <cstddef>
#include <vector>

namespace oneshot::design {

/// Row-major matrix whose size is known only at run time (parsed files, JSON output).
struct DenseMatrix {
  std::size_t rows = 0;        ///< Number of rows.
  std::size_t cols = 0;        ///< Number of columns.
  std::vector<double> values;  ///< rows × cols entries, row-major.

  /// rows × cols zeros.
  static DenseMatrix zeros(std::size_t r, std::size_t c) { return {r, c, std::vector<double>(r * c, 0.0)}; }
  /// Entry (i, j).
  double& operator()(std::size_t i, std::size_t j) { return values[i * cols + j]; }
  /// Entry (i, j).
  double operator()(std::size_t i, std::size_t j) const { return values[i * cols + j]; }
  /// Same shape and entries.
  bool operator==(const DenseMatrix& o) const {
    return rows == o.rows && cols == o.cols && values == o.values;
  }
};

}  // namespace oneshot::design
