/// @file petc_exectime_host_test.cpp
/// @brief The host half of `petc exectime` (no QEMU): the multiplicities it measures come
///        from the study's runs, and the node in float follows the node in double.
#include <gtest/gtest.h>

#include <algorithm>

#include "petc_exectime.hpp"
#include "petc_test_support.hpp"

namespace oneshot::sim::petc {
namespace {

TEST(PetcExectimeHost, MultiplicitiesComeFromTheStudy) {
  const ArrivalPlan plan = plan_arrivals(default_setup(), ExectimeOptions{});
  // The largest N equals the study's N_max metric over cases 3, 4, 5 at the same seed.
  double n_max = 0;
  const std::vector<std::string>& names = metric_names();
  const std::size_t at = static_cast<std::size_t>(std::find(names.begin(), names.end(), "N_max") - names.begin());
  ASSERT_LT(at, names.size());
  for (const CaseSpec& c : default_cases())
    if (c.name == "3" || c.name == "4" || c.name == "5") n_max = std::max(n_max, run_case(default_setup(), c, 1).at(at));
  EXPECT_EQ(plan.n_max, static_cast<std::uint32_t>(n_max));
  EXPECT_GE(plan.n_typical, 1U);
  EXPECT_LE(plan.n_typical, plan.n_max);
  ASSERT_GE(plan.k.size(), 3U);
  EXPECT_EQ(plan.k[0], 0U);
  EXPECT_EQ(plan.k[1], 1U);
  // N = 1, 2, 97 and H are always measured, beside the study's median, mean and largest.
  std::vector<std::uint32_t> ns;
  for (std::size_t a = 1; a < plan.k.size(); ++a) ns.push_back(plan.k[a] - plan.k[a - 1]);
  for (std::uint32_t n : {1U, 2U, 97U, static_cast<std::uint32_t>(kHorizon), plan.n_max, plan.n_typical})
    EXPECT_NE(std::find(ns.begin(), ns.end(), n), ns.end()) << n;
  EXPECT_TRUE(std::is_sorted(ns.begin(), ns.end()));
  EXPECT_THROW(plan_arrivals(default_setup(), ExectimeOptions{"2", 1, {}, "", ""}), std::invalid_argument);
  EXPECT_THROW(plan_arrivals(default_setup(), ExectimeOptions{"4", 1, {400}, "", ""}), std::invalid_argument);
}

TEST(PetcExectimeHost, FloatNodeFollowsDouble) {
  const ArrivalPlan plan = plan_arrivals(default_setup(), ExectimeOptions{});
  const std::vector<HostArrival> h = host_arrivals(default_setup(), plan);
  ASSERT_EQ(h.size(), plan.k.size());
  double worst = 0;
  for (std::size_t a = 0; a < h.size(); ++a) {
    EXPECT_EQ(h[a].multiplicity, a == 0 ? 0U : plan.k[a] - plan.k[a - 1]);
    EXPECT_EQ(h[a].cascade.size(), kHorizon + 1);
    worst = std::max(worst, h[a].max_rel_diff_double);
  }
  // Single precision through N = 97 predictions and a 201-step cascade: measured 1.7e-5
  // relative to the largest input of the cascade.
  EXPECT_LT(worst, 1e-4);
  EXPECT_GT(worst, 0.0);  // the float node is not the double node in disguise
}

}  // namespace
}  // namespace oneshot::sim::petc
