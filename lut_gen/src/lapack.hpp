/// @file lapack.hpp
/// @brief LAPACKE with std::complex as its complex types (host design step only).
#pragma once

#include <complex>

#ifndef lapack_complex_float
#define lapack_complex_float std::complex<float>
#endif
#ifndef lapack_complex_double
#define lapack_complex_double std::complex<double>
#endif
#include <lapacke.h>
