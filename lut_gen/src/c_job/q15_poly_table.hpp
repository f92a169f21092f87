/// @file q15_poly_table.hpp
/// @brief The q15 variants' discretization table: for every grid interval [k·g, (k+1)·g) one
///        polynomial per free entry of Φ, Γ, Q_d in r = (τ − k·g)/g,
///            v(τ) = Σ_j c_kj r^j,  c_k0 = v(k·g) exactly (then rounded once),
///        fitted to the exact double discretization and of the lowest degree (per entry, common
///        to all intervals) whose error stays below 1/4 LSB of the entry's 16-bit format over
///        the interval (checked on a dense grid). Coefficients share one binary point per entry
///        (a block exponent) chosen so that Horner's |v| < 2^15 at every step. One table
///        look-up and a few 16×16→32 steps then give Φ(τ), Γ(τ), Q_d(τ) for any τ in the
///        range — no composition of two intervals in 16 bits. The nearest variant keeps degree 0.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "c_job/c_arith.hpp"
#include "oneshot/design/controller_synthesis.hpp"
#include "oneshot/design/plant_description.hpp"

namespace oneshot::design::cjob {

/// One free entry of the interval triple: d-><member>[index], quantity q.
struct Q15Member {
  std::string member;  ///< "phi", "gamma" or "qd".
  std::size_t index;   ///< Position in that array.
  std::size_t i, j;    ///< Matrix entry.
  Qty q;               ///< Its quantity (format).
};

/// One stored polynomial (members with identical values and formats share it).
struct Q15Slot {
  std::vector<std::size_t> members;  ///< Indices into Q15PolyTable::members.
  int degree = 0;                    ///< Highest power of r.
  int frac = 0;                      ///< Coefficients' binary point.
  std::size_t offset = 0;            ///< First coefficient (c_0) in a row.
  double max_error_lsb = 0;          ///< Fit error in LSB of the destination format (measured).
};

/// The designed table.
struct Q15PolyTable {
  std::vector<Q15Member> members;              ///< Triple entries, in triple order.
  std::vector<Q15Slot> slots;                  ///< Stored polynomials.
  std::vector<std::vector<long long>> rows;    ///< Per interval k = 0 … K: every slot's c_0 … c_D.
  std::size_t width = 0;                       ///< Coefficients per row.
};

/// Exact values (double, the generic discretizer's matrix exponential) of every member at each
/// time t_us (integers), one row per time.
std::vector<std::vector<double>> exact_member_values(const PlantDescription& plant, const DesignResult& design,
                                                     const std::vector<Q15Member>& members,
                                                     const std::vector<double>& t_us);

/// The members that share one stored polynomial: a group opens at the first member not yet
/// grouped and takes every later ungrouped member b with same(a, b) (a its first member);
/// groups in the order of their first members. Shared by the q15 table and float_poly.
std::vector<std::vector<std::size_t>> shared_member_groups(std::size_t count,
                                                           const std::function<bool(std::size_t, std::size_t)>& same);

/// Least-squares a_e (e ∈ exps) of y(s) on the basis s^e: normal equations solved by
/// Gauss-Jordan with partial pivoting (a singular column gives 0). Keep s in [0, 1] so that
/// they stay well conditioned up to degree 6. Shared by the q15 table and float_poly.
std::vector<double> least_squares(const std::vector<double>& s, const std::vector<double>& y,
                                  const std::vector<int>& exps);

/// Designs the table for intervals k = 0 … range/g (the last one is used at r = 0 only).
Q15PolyTable design_q15_poly_table(const PlantDescription& plant, const DesignResult& design, const Arith& ar,
                                   std::int32_t g_us, std::int32_t range_us, std::vector<Q15Member> members,
                                   bool nearest);

}  // namespace oneshot::design::cjob
