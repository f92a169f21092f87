/// @file status_test.cpp
/// @brief Status severity: worst_of is a total order's maximum, kSingular is never masked,
///        and the filters report the worst status of a job.
#include <gtest/gtest.h>

#include "oneshot/complete_kalman.hpp"
#include "oneshot/generated/plant_tables.hpp"
#include "oneshot/half_kalman.hpp"
#include "oneshot/status.hpp"
#include "oneshot/table_discretizer.hpp"

namespace oneshot {
namespace {

constexpr Status kAll[] = {Status::kOk,        Status::kExtended, Status::kClamped,     Status::kSingular,
                           Status::kOutOfRange, Status::kOverflow, Status::kNotConverged, Status::kNonFinite};

TEST(Status, WorstOfIsCommutativeAssociativeAndNeverMilder) {
  for (Status a : kAll)
    for (Status b : kAll) {
      EXPECT_EQ(worst_of(a, b), worst_of(b, a));
      EXPECT_GE(severity(worst_of(a, b)), severity(a));
      EXPECT_GE(severity(worst_of(a, b)), severity(b));
      EXPECT_TRUE(worst_of(a, b) == a || worst_of(a, b) == b);
      for (Status c : kAll) EXPECT_EQ(worst_of(worst_of(a, b), c), worst_of(a, worst_of(b, c)));
    }
  // Distinct severities: a total order.
  for (Status a : kAll) {
    for (Status b : kAll) {
      if (a != b) {
        EXPECT_NE(severity(a), severity(b));
      }
    }
  }
}

TEST(Status, SingularIsNeverMasked) {
  // WHEN kSingular appears anywhere in a sequence THEN the result is kSingular or the one
  // more severe statuses (kOutOfRange: no result at all; kNonFinite: state reset), never an
  // exact or approximate one
  for (Status before : kAll)
    for (Status after : kAll) {
      const Status s = first_failure(first_failure(before, Status::kSingular), after);
      EXPECT_TRUE(s == Status::kSingular || s == Status::kOutOfRange || s == Status::kNonFinite)
          << to_string(before) << " " << to_string(after);
      EXPECT_FALSE(is_exact(s));
    }
  EXPECT_EQ(first_failure(Status::kExtended, Status::kSingular), Status::kSingular);
  EXPECT_EQ(first_failure(Status::kClamped, Status::kSingular), Status::kSingular);
  EXPECT_EQ(first_failure(Status::kOverflow, Status::kSingular), Status::kSingular);
}

TEST(Status, CompleteFilterReportsASingularCorrectionAfterAnExtendedPrediction) {
  // GIVEN the complete filter on the reference table with R so negative that the innovation
  // variance is not positive, and a job whose interval a + b exceeds the table (kExtended)
  using K = generated::PlantConstants<double>;
  using Disc = TableDiscretizer<K::Format, generated::PlantStructure, double>;
  const Disc table(K::kTable);
  auto design = K::kDesign;
  design.r(0, 0) = -1e3;
  CompleteKalman<K::Format, generated::PlantStructure, Disc> filter(design, table, NoiseModel::kExact);
  HalfKalman<K::Format, generated::PlantStructure, Disc> half(design, table, NoiseModel::kExact);
  Vector<double, 1> y;
  y[0] = 0.1;
  const std::int32_t h = design.period_us;
  ASSERT_EQ(filter.update(h / 2, y), Status::kSingular);
  filter.set_applied_input(Vector<double, 1>{});
  // WHEN a = h/2 and b = h − τ = 0.9 h: a + b > range (extended), then the singular correction
  // THEN the job reports kSingular, not kExtended (which would count as exact)
  EXPECT_EQ(filter.update(h / 10, y), Status::kSingular);
  // AND a half-filter job with τ < 0 (clamped) and a singular correction reports kSingular
  EXPECT_EQ(half.update(-h / 10, y), Status::kSingular);
}

}  // namespace
}  // namespace oneshot
