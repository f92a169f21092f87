/// @file matrix.hpp
/// @brief Fixed-size matrix with inline storage; dimensions are template parameters.
///
/// Sizes are checked at compile time: a product of mismatched shapes does not compile.
/// Storage is row-major and inline (no heap). Element operators use the scalar's own
/// arithmetic; mixed-format and structure-aware kernels live in structured_ops.hpp.
#pragma once

#include <cstddef>

#include "oneshot/scalar_traits.hpp"

namespace oneshot {

/// Tag: construct without initialising the entries (the caller writes every one).
struct NoInit {};

/// R×C matrix of scalars S, row-major, inline storage.
template <typename S, std::size_t R, std::size_t C>
class Matrix {
  static_assert(R > 0 && C > 0, "matrix dimensions must be positive");

 public:
  using Scalar = S;
  static constexpr std::size_t kRows = R;   ///< Number of rows.
  static constexpr std::size_t kCols = C;   ///< Number of columns.
  static constexpr std::size_t kSize = R * C;  ///< Number of entries.

  /// All entries zero (value-initialised).
  constexpr Matrix() : data_{} {}

  /// Entries left unset: for kernels that write every entry (saves a zero fill).
  explicit Matrix(NoInit) {}  // NOLINT(cppcoreguidelines-pro-type-member-init)

  /// Entries from a row-major array.
  constexpr explicit Matrix(const S (&row_major)[R * C]) : data_{} {
    for (std::size_t k = 0; k < R * C; ++k) data_[k] = row_major[k];
  }

  /// Zero matrix.
  static constexpr Matrix zeros() { return Matrix{}; }

  /// Identity (square only).
  static constexpr Matrix identity() {
    static_assert(R == C, "identity needs a square matrix");
    Matrix m;
    for (std::size_t i = 0; i < R; ++i) m(i, i) = ScalarTraits<S>::one();
    return m;
  }

  /// Entry (i, j).
  constexpr S& operator()(std::size_t i, std::size_t j) { return data_[i * C + j]; }
  /// Entry (i, j).
  constexpr const S& operator()(std::size_t i, std::size_t j) const { return data_[i * C + j]; }
  /// Entry k in row-major order (vectors: the k-th component).
  constexpr S& operator[](std::size_t k) { return data_[k]; }
  /// Entry k in row-major order (vectors: the k-th component).
  constexpr const S& operator[](std::size_t k) const { return data_[k]; }

  /// Pointer to the row-major storage.
  constexpr const S* data() const { return data_; }

  /// Transpose.
  constexpr Matrix<S, C, R> transposed() const {
    Matrix<S, C, R> t;
    for (std::size_t i = 0; i < R; ++i)
      for (std::size_t j = 0; j < C; ++j) t(j, i) = (*this)(i, j);
    return t;
  }

  /// The BR×BC block starting at (I0, J0); bounds checked at compile time.
  template <std::size_t I0, std::size_t J0, std::size_t BR, std::size_t BC>
  constexpr Matrix<S, BR, BC> block() const {
    static_assert(I0 + BR <= R && J0 + BC <= C, "block outside the matrix");
    Matrix<S, BR, BC> b;
    for (std::size_t i = 0; i < BR; ++i)
      for (std::size_t j = 0; j < BC; ++j) b(i, j) = (*this)(I0 + i, J0 + j);
    return b;
  }

  /// Writes `b` at (I0, J0); bounds checked at compile time.
  template <std::size_t I0, std::size_t J0, std::size_t BR, std::size_t BC>
  constexpr void set_block(const Matrix<S, BR, BC>& b) {
    static_assert(I0 + BR <= R && J0 + BC <= C, "block outside the matrix");
    for (std::size_t i = 0; i < BR; ++i)
      for (std::size_t j = 0; j < BC; ++j) (*this)(I0 + i, J0 + j) = b(i, j);
  }

  /// Entry-wise sum.
  friend constexpr Matrix operator+(const Matrix& a, const Matrix& b) {
    Matrix s;
    for (std::size_t k = 0; k < R * C; ++k) s.data_[k] = a.data_[k] + b.data_[k];
    return s;
  }
  /// Entry-wise difference.
  friend constexpr Matrix operator-(const Matrix& a, const Matrix& b) {
    Matrix s;
    for (std::size_t k = 0; k < R * C; ++k) s.data_[k] = a.data_[k] - b.data_[k];
    return s;
  }
  /// Negation.
  friend constexpr Matrix operator-(const Matrix& a) {
    Matrix s;
    for (std::size_t k = 0; k < R * C; ++k) s.data_[k] = -a.data_[k];
    return s;
  }
  /// Scalar multiple.
  friend constexpr Matrix operator*(const Matrix& a, S k) {
    Matrix s;
    for (std::size_t i = 0; i < R * C; ++i) s.data_[i] = a.data_[i] * k;
    return s;
  }
  /// Matrix product (dense, same scalar); inner dimensions checked at compile time.
  template <std::size_t C2>
  friend constexpr Matrix<S, R, C2> operator*(const Matrix& a, const Matrix<S, C, C2>& b) {
    Matrix<S, R, C2> p;
    for (std::size_t i = 0; i < R; ++i)
      for (std::size_t j = 0; j < C2; ++j) {
        S acc = a(i, 0) * b(0, j);
        for (std::size_t k = 1; k < C; ++k) acc = acc + a(i, k) * b(k, j);
        p(i, j) = acc;
      }
    return p;
  }

 private:
  S data_[R * C];
};

/// Column vector.
template <typename S, std::size_t N>
using Vector = Matrix<S, N, 1>;

/// Entry-wise format conversion.
template <typename To, typename From, std::size_t R, std::size_t C>
constexpr Matrix<To, R, C> convert_matrix(const Matrix<From, R, C>& m) {
  Matrix<To, R, C> out;
  for (std::size_t k = 0; k < R * C; ++k) out[k] = convert<To>(m[k]);
  return out;
}

/// Makes a square matrix exactly symmetric from its upper triangle.
template <typename S, std::size_t N>
constexpr void mirror_upper(Matrix<S, N, N>& m) {
  for (std::size_t i = 0; i < N; ++i)
    for (std::size_t j = i + 1; j < N; ++j) m(j, i) = m(i, j);
}

/// A symmetric result: m(i, j) = entry(i, j) for j ≥ i (row by row), then mirror_upper(m).
/// entry may read m(i, j) itself (in-place updates of the upper triangle).
template <typename S, std::size_t N, typename Entry>
[[gnu::always_inline]] constexpr void fill_symmetric(Matrix<S, N, N>& m, Entry entry) {
  for (std::size_t i = 0; i < N; ++i)
    for (std::size_t j = i; j < N; ++j) m(i, j) = entry(i, j);
  mirror_upper(m);
}

}  // namespace oneshot
