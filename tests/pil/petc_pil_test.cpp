/// @file petc_pil_test.cpp
/// @brief The petc controller node on the Cortex-M4F image under QEMU: one NUMRE arrival per
///        request, its instruction count (positive, growing with N, a stable multiple of the
///        node's multiply-adds), the same arrival bit for bit on the host build of the node in
///        float, and the image inside the MPS2's 64 KB of RAM.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>

#include "petc_exectime.hpp"

namespace oneshot::sim::petc {
namespace {

const nlohmann::json& result() {
  static const nlohmann::json j = [] {
    PetcOptions o;
    return run_exectime(make_setup(o), ExectimeOptions{});
  }();
  return j;
}

TEST(PetcPil, ArrivalInstructionsGrowWithMultiplicity) {
  const nlohmann::json& j = result();
  const auto& a = j.at("arrivals");
  ASSERT_GE(a.size(), 4U);  // the first arrival (N = 0), N = 1, the median, the largest
  EXPECT_EQ(a[0].at("N").get<std::uint32_t>(), 0U);
  EXPECT_EQ(a[1].at("N").get<std::uint32_t>(), 1U);
  EXPECT_EQ(a.back().at("N").get<std::uint32_t>(), j.at("n_max").get<std::uint32_t>());
  for (std::size_t i = 0; i < a.size(); ++i) {
    const auto insns = a[i].at("instructions").get<std::uint64_t>();
    const auto macs = a[i].at("macs").get<std::uint64_t>();
    EXPECT_GT(insns, 0U);
    EXPECT_GT(macs, 0U);
    EXPECT_TRUE(std::isfinite(a[i].at("instructions_per_mac").get<double>()));
    if (i > 1) {
      EXPECT_GT(a[i].at("N").get<std::uint32_t>(), a[i - 1].at("N").get<std::uint32_t>());
      EXPECT_GT(insns, a[i - 1].at("instructions").get<std::uint64_t>()) << "arrival " << i;
      EXPECT_GT(macs, a[i - 1].at("macs").get<std::uint64_t>());
    }
  }
  // Each predicted period runs the same code on the same dense multiply-adds (2n³ + n² + n):
  // the instructions per multiply-add of the extra periods between the last two N equal
  // those between N = 1 and the one before (a few instructions out of ~16,000 per period).
  const auto d = [&](std::size_t hi, std::size_t lo, const char* f) {
    return static_cast<double>(a[hi].at(f).get<std::uint64_t>()) - static_cast<double>(a[lo].at(f).get<std::uint64_t>());
  };
  const std::size_t last = a.size() - 1;
  const std::size_t mid = last - 1;
  ASSERT_GT(mid, 1U);
  const double per_mac_low = d(mid, 1, "instructions") / d(mid, 1, "macs");
  const double per_mac_high = d(last, mid, "instructions") / d(last, mid, "macs");
  EXPECT_GT(per_mac_high, 1.0);  // an FPU multiply-add is at least one instruction plus loads
  EXPECT_NEAR(per_mac_low / per_mac_high, 1.0, 1e-4) << per_mac_low << " vs " << per_mac_high;  // measured 4.6e-6
}

TEST(PetcPil, ArrivalBitIdenticalToHostFloat) {
  const nlohmann::json& j = result();
  for (const auto& a : j.at("arrivals")) {
    EXPECT_TRUE(a.at("bit_identical_x_hat").get<bool>()) << a.dump();
    EXPECT_TRUE(a.at("bit_identical_cascade").get<bool>()) << a.dump();
    EXPECT_TRUE(a.at("bit_identical_d_hat").get<bool>()) << a.dump();
    EXPECT_EQ(a.at("macs"), a.at("host_macs"));
  }
  EXPECT_TRUE(j.at("all_bit_identical_to_host_float").get<bool>());
}

TEST(PetcPil, ImageFitsTheBoard) {
  const nlohmann::json& j = result();
  const auto ram = j.at("ram_static_bytes").get<std::size_t>();
  EXPECT_GT(ram, j.at("node_bytes").get<std::size_t>());
  EXPECT_GT(j.at("stack_peak_bytes").get<int>(), 0);
  ASSERT_TRUE(j.contains("stack_bound_bytes"));
  EXPECT_GE(j.at("stack_bound_bytes").get<std::size_t>(), static_cast<std::size_t>(j.at("stack_peak_bytes").get<int>()));
  EXPECT_LE(ram + j.at("stack_bound_bytes").get<std::size_t>(), j.at("ram_limit_bytes").get<std::size_t>());
  EXPECT_GT(j.at("flash_bytes").get<std::size_t>(), 0U);
}

}  // namespace
}  // namespace oneshot::sim::petc
