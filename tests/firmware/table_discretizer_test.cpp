/// @file table_discretizer_test.cpp
/// @brief The look-up table against the generic routine at every grid point and between
///        them, its out-of-range policy, and structured versus dense evaluation.
#include <gtest/gtest.h>

#include <algorithm>
#include <iostream>

#include "oneshot/design/controller_synthesis.hpp"
#include "oneshot/design/fixed_size.hpp"
#include "oneshot/design/structure_analysis.hpp"
#include "oneshot/design/table_builder.hpp"
#include "oneshot/generated/plant_tables.hpp"
#include "oneshot/generic_discretizer.hpp"
#include "oneshot/plant_structure.hpp"
#include "oneshot/table_discretizer.hpp"
#include "support/eigen_reference.hpp"
#include "support/invariant_violation.hpp"
#include "support/test_plants.hpp"

namespace oneshot {
namespace {

using generated::PlantConstants;
using generated::PlantStructure;
using F64 = UniformFormat<double>;

struct Worst {
  double phi = 0, gamma = 0, qd = 0;
};

/// Compares `lut` with the double generic routine on `taus`.
template <typename Lut, std::size_t N, std::size_t M>
Worst compare(const Lut& lut, const GenericDiscretizer<F64, N, M>& gen, const std::vector<std::int32_t>& taus) {
  Worst w;
  for (std::int32_t tau : taus) {
    typename Lut::Triple got;
    Discretization<F64, N, M> ref;
    const Status s = lut.discretize(tau, got, WithQd::kYes);
    EXPECT_TRUE(is_exact(s)) << "tau " << tau;
    EXPECT_EQ(gen.discretize(tau, ref, WithQd::kYes), Status::kOk);
    w.phi = std::max(w.phi, test::relative_error(test::to_eigen(got.phi), test::to_eigen(ref.phi)));
    w.gamma = std::max(w.gamma, test::relative_error(test::to_eigen(got.gamma), test::to_eigen(ref.gamma)));
    if (tau > 0) w.qd = std::max(w.qd, test::relative_error(test::to_eigen(got.qd), test::to_eigen(ref.qd)));
  }
  return w;
}

/// Every grid point, its neighbours ±1 µs, the midpoints, and every 7th µs of the range.
std::vector<std::int32_t> grid_and_between(std::int32_t g, std::int32_t range) {
  std::vector<std::int32_t> t;
  for (std::int32_t k = 0; k <= range; k += g) {
    t.push_back(k);
    if (k > 0) t.push_back(k - 1);
    if (k < range) {
      t.push_back(k + 1);
      t.push_back(k + g / 2);
    }
  }
  for (std::int32_t k = 0; k <= range; k += 7) t.push_back(k);
  return t;
}

template <typename S>
void check_reference_table(double tol_transition, double tol_qd) {
  using K = PlantConstants<S>;
  const auto plant = design::reference_plant();
  const auto d = design::synthesize(plant);
  const GenericDiscretizer<F64, 2, 1> gen(design::continuous_model_per_us<double, 2, 1>(plant, d));
  const TableDiscretizer<typename K::Format, PlantStructure, S> lut(K::kTable);
  const Worst w = compare(lut, gen, grid_and_between(K::kTable.granularity_us, K::kTable.range_us));
  std::cout << "[ measured ] reference table (" << (sizeof(S) == 4 ? "float" : "double")
            << ") max rel err Phi " << w.phi << ", Gamma " << w.gamma << ", Qd " << w.qd << "\n";
  EXPECT_LT(w.phi, tol_transition);
  EXPECT_LT(w.gamma, tol_transition);
  EXPECT_LT(w.qd, tol_qd);
}

TEST(TableDiscretizer, ReferenceFloatAtAndBetweenGridPoints) { check_reference_table<float>(1e-6, 2e-6); }
TEST(TableDiscretizer, ReferenceDoubleAtAndBetweenGridPoints) { check_reference_table<double>(1e-14, 1e-13); }

TEST(TableDiscretizer, ReferenceTableFitsTheBudget) {
  // The bound is 1024 B; the reference plant asks for 256 B (table.max_bytes).
  EXPECT_LE(table_bytes(PlantConstants<float>::kTable, 2, 1), 256U);
  EXPECT_EQ(PlantConstants<float>::kTable.granularity_us, 1000);
  EXPECT_EQ(PlantConstants<float>::kTable.range_us, 50000);
}

template <typename S, std::size_t N, std::size_t M>
void check_runtime_table(const design::PlantDescription& plant, double tol_transition, double tol_qd) {
  const auto d = design::synthesize(plant);
  const auto patterns = design::analyse_structure(plant, d);
  const auto table = design::build_table<S>(plant, d, patterns);
  const GenericDiscretizer<F64, N, M> gen(design::continuous_model_per_us<double, N, M>(plant, d));
  const TableDiscretizer<UniformFormat<S>, DenseStructure<N, M, 1>, S> lut(table.view());
  const Worst w = compare(lut, gen, grid_and_between(table.granularity_us, table.range_us));
  std::cout << "[ measured ] " << plant.name << " table (" << (sizeof(S) == 4 ? "float" : "double")
            << ", " << table.bytes() << " B) max rel err Phi " << w.phi << ", Gamma " << w.gamma << ", Qd " << w.qd
            << "\n";
  EXPECT_LT(w.phi, tol_transition);
  EXPECT_LT(w.gamma, tol_transition);
  EXPECT_LT(w.qd, tol_qd);
}

TEST(TableDiscretizer, DampedOscillatorFloat) { check_runtime_table<float, 2, 1>(test::damped_oscillator(), 2e-5, 2e-5); }
TEST(TableDiscretizer, DampedOscillatorDouble) { check_runtime_table<double, 2, 1>(test::damped_oscillator(), 1e-12, 1e-12); }
TEST(TableDiscretizer, UnstablePoleFloat) { check_runtime_table<float, 2, 1>(test::unstable_plant(), 2e-5, 2e-5); }
TEST(TableDiscretizer, UnstablePoleDouble) { check_runtime_table<double, 2, 1>(test::unstable_plant(), 1e-12, 1e-12); }
TEST(TableDiscretizer, ThreeStateFloat) { check_runtime_table<float, 3, 1>(test::three_state_plant(), 2e-5, 2e-5); }
TEST(TableDiscretizer, ThreeStateDouble) { check_runtime_table<double, 3, 1>(test::three_state_plant(), 1e-12, 1e-12); }

class OutOfRangeTest : public ::testing::Test {
 protected:
  using K = PlantConstants<double>;
  const design::PlantDescription plant_ = design::reference_plant();
  const design::DesignResult design_ = design::synthesize(plant_);
  const GenericDiscretizer<F64, 2, 1> gen_{design::continuous_model_per_us<double, 2, 1>(plant_, design_)};
  const std::int32_t range_ = K::kTable.range_us;

  template <typename Lut>
  Discretization<F64, 2, 1> at(const Lut& lut, std::int32_t tau, Status expected) {
    Discretization<F64, 2, 1> d;
    EXPECT_EQ(lut.discretize(tau, d, WithQd::kYes), expected) << "tau " << tau;
    return d;
  }
  void expect_equal_to_generic(const Discretization<F64, 2, 1>& d, std::int32_t tau) {
    Discretization<F64, 2, 1> ref;
    ASSERT_EQ(gen_.discretize(tau, ref, WithQd::kYes), Status::kOk);
    EXPECT_LT(test::relative_error(test::to_eigen(d.phi), test::to_eigen(ref.phi)), 1e-13) << "tau " << tau;
    EXPECT_LT(test::relative_error(test::to_eigen(d.gamma), test::to_eigen(ref.gamma)), 1e-13) << "tau " << tau;
    EXPECT_LT(test::relative_error(test::to_eigen(d.qd), test::to_eigen(ref.qd)), 1e-12) << "tau " << tau;
  }
};

TEST_F(OutOfRangeTest, NegativeTauIsClampedToZero) {
  const TableDiscretizer<F64, PlantStructure, double> lut(K::kTable);
  const auto d = at(lut, -1234, Status::kClamped);
  expect_equal_to_generic(d, 0);
}

TEST_F(OutOfRangeTest, BeyondRangeIsExtendedExactlyByComposition) {
  const TableDiscretizer<F64, PlantStructure, double> lut(K::kTable);
  for (std::int32_t tau : {range_ + 1, range_ + 17'321, 2 * range_, 2 * range_ - 3, 3 * range_ + 999, 4 * range_}) {
    expect_equal_to_generic(at(lut, tau, Status::kExtended), tau);
  }
}

TEST_F(OutOfRangeTest, FarBeyondRangeIsClampedToTheLargestSupported) {
  const TableDiscretizer<F64, PlantStructure, double> lut(K::kTable);
  const std::int32_t largest = (TableDiscretizer<F64, PlantStructure, double>::kMaxExtensions + 1) * range_;
  expect_equal_to_generic(at(lut, largest + 1, Status::kClamped), largest);
  expect_equal_to_generic(at(lut, 1'000'000'000, Status::kClamped), largest);
}

TEST_F(OutOfRangeTest, ClampPolicyClampsToTheRange) {
  const TableDiscretizer<F64, PlantStructure, double, ::oneshot::OutOfRange::kClamp> lut(K::kTable);
  expect_equal_to_generic(at(lut, range_ + 1, Status::kClamped), range_);
  expect_equal_to_generic(at(lut, range_, Status::kOk), range_);
}

TEST(TableDiscretizer, NearestPolicyRoundsTauToTheGridAndIsExactThere) {
  // GIVEN the reference table with the nearest-grid-point policy
  using K = PlantConstants<double>;
  const TableDiscretizer<F64, PlantStructure, double, OutOfRange::kExtend, SubGrid::kNearest> nearest(K::kTable);
  const TableDiscretizer<F64, PlantStructure, double> exact(K::kTable);
  const std::int32_t g = K::kTable.granularity_us;
  // WHEN τ is quantized THEN it lands on the nearest multiple of g (ties away from zero), negatives too
  EXPECT_EQ(nearest.quantize(0), 0);
  EXPECT_EQ(nearest.quantize(g / 2 - 1), 0);
  EXPECT_EQ(nearest.quantize(g / 2), g);
  EXPECT_EQ(nearest.quantize(3 * g + g / 2 - 1), 3 * g);
  EXPECT_EQ(nearest.quantize(3 * g + g / 2 + 1), 4 * g);
  EXPECT_EQ(nearest.quantize(-17), 0);
  EXPECT_EQ(nearest.quantize(-(g / 2) + 1), 0);
  EXPECT_EQ(nearest.quantize(-(g / 2)), -g);
  EXPECT_EQ(nearest.quantize(-3 * g - g / 2 + 1), -3 * g);
  EXPECT_EQ(nearest.quantize(-3 * g - g / 2), -4 * g);
  EXPECT_EQ(exact.quantize(3 * g + 123), 3 * g + 123);
  // AND on the grid (also beyond the range) both policies give the same triple bit for bit
  for (std::int32_t k = 0; k <= 2 * K::kTable.range_us / g; ++k) {
    Discretization<F64, 2, 1> a;
    Discretization<F64, 2, 1> b;
    EXPECT_EQ(nearest.discretize(k * g, a, WithQd::kYes), exact.discretize(k * g, b, WithQd::kYes));
    for (std::size_t i = 0; i < 4; ++i) {
      EXPECT_EQ(a.phi[i], b.phi[i]) << "tau " << k * g;
      EXPECT_EQ(a.qd[i], b.qd[i]) << "tau " << k * g;
    }
    EXPECT_EQ(a.gamma[0], b.gamma[0]);
    EXPECT_EQ(a.gamma[1], b.gamma[1]);
  }
}

TEST(TableDiscretizer, NearestPolicyRefusesAnUnquantizedTau) {
  // The filters quantize τ before asking; a caller that forgets is an invariant violation.
  using K = PlantConstants<double>;
  const TableDiscretizer<F64, PlantStructure, double, OutOfRange::kExtend, SubGrid::kNearest> nearest(K::kTable);
  Discretization<F64, 2, 1> d;
  EXPECT_THROW((void)nearest.discretize(K::kTable.granularity_us + 1, d, WithQd::kYes), test::InvariantViolation);
}

TEST(TableDiscretizer, StructuredAndDenseEvaluationAgreeBitForBit) {
  using K = PlantConstants<float>;
  const TableDiscretizer<K::Format, PlantStructure, float> structured(K::kTable);
  const TableDiscretizer<K::Format, DenseStructure<2, 1, 1>, float> dense(K::kTable);
  for (std::int32_t tau = 0; tau <= 2 * K::kTable.range_us; tau += 37) {
    Discretization<K::Format, 2, 1> a;
    Discretization<K::Format, 2, 1> b;
    ASSERT_EQ(structured.discretize(tau, a, WithQd::kYes), dense.discretize(tau, b, WithQd::kYes));
    for (std::size_t k = 0; k < 4; ++k) {
      EXPECT_EQ(a.phi[k], b.phi[k]);
      EXPECT_EQ(a.qd[k], b.qd[k]);
    }
    EXPECT_EQ(a.gamma[0], b.gamma[0]);
    EXPECT_EQ(a.gamma[1], b.gamma[1]);
  }
}

TEST(TableDiscretizer, StructureClaimsAreChecked) {
  // A structure claiming Φ₀₁ ≡ 0 contradicts the reference table (Φ₀₁ = −23.8 t).
  struct WrongStructure : DenseStructure<2, 1, 1> {
    using PhiPattern = Pattern<2, 2, 0x2, 0x0>;
  };
  using K = PlantConstants<float>;
  static_assert(!TableDiscretizer<K::Format, WrongStructure, float>::maps_match_structure(K::kTable));
  EXPECT_THROW((TableDiscretizer<K::Format, WrongStructure, float>(K::kTable)), test::InvariantViolation);
}

}  // namespace
}  // namespace oneshot
