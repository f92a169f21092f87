/// @file pil_link_test.cpp
/// @brief The processor-in-the-loop link against a firmware image running under QEMU:
///        framing and escaping, resynchronisation after a corrupt or lost byte, lost
///        replies, and the firmware's self-description.
#include <gtest/gtest.h>

#include <cstdint>
#include <string>
#include <vector>

#include "oneshot/sim/pil_link.hpp"

namespace oneshot::sim {
namespace {

namespace pil = app::pil;

PilOptions options_for(const std::string& target) {
  PilOptions o;
  o.target = target;
  o.timeout_ms = 200;  // a resend costs one timeout; duplicates are answered from the cache
  return o;
}

/// A payload exercising the byte stuffing: flags and escapes among ordinary bytes.
pil::Frame awkward_payload(std::uint8_t salt) {
  pil::Frame f;
  const std::uint8_t special[] = {pil::kFlag, pil::kEscape, 0x00, 0xFF, 0x5E, 0x5D};
  for (std::size_t i = 0; i < 48; ++i) {
    f.payload[i] = i % 3 == 0 ? special[(i / 3 + salt) % 6] : static_cast<std::uint8_t>(i * 37 + salt);
  }
  f.length = 48;
  return f;
}

void expect_echo(PilLink& link, std::uint8_t salt) {
  const pil::Frame q = awkward_payload(salt);
  const pil::Frame r = link.request(pil::Type::kEcho, q);
  ASSERT_EQ(r.length, q.length);
  for (std::size_t i = 0; i < q.length; ++i) EXPECT_EQ(r.payload[i], q.payload[i]) << "byte " << i;
}

class PilLinkTest : public ::testing::TestWithParam<std::string> {};

TEST_P(PilLinkTest, DescribesItselfAndEchoesStuffedBytes) {
  PilLink link(options_for(GetParam()));
  EXPECT_EQ(link.info().protocol, pil::kProtocolVersion);
  EXPECT_EQ(link.info().target, GetParam());
  EXPECT_EQ(link.info().format, "float");
  EXPECT_EQ(link.info().discretizer, "table");
  EXPECT_EQ(link.info().n, 2);
  EXPECT_EQ(link.info().m, 1);
  EXPECT_EQ(link.info().p, 1);
  for (std::uint8_t salt = 0; salt < 6; ++salt) expect_echo(link, salt);
  EXPECT_EQ(link.resends(), 0U);
}

TEST_P(PilLinkTest, ResynchronisesAfterACorruptByte) {
  PilLink link(options_for(GetParam()));
  link.inject(LinkFault::kCorruptByte);
  expect_echo(link, 1);
  EXPECT_EQ(link.resends(), 1U);  // the damaged frame was dropped by its CRC, the resend answered
  expect_echo(link, 2);
  EXPECT_EQ(link.resends(), 1U);
}

TEST_P(PilLinkTest, ResynchronisesAfterALostByte) {
  PilLink link(options_for(GetParam()));
  link.inject(LinkFault::kDropByte);
  expect_echo(link, 3);
  EXPECT_EQ(link.resends(), 1U);
  expect_echo(link, 4);
  EXPECT_EQ(link.resends(), 1U);
}

/// Configures approach B and runs three identical jobs; `fault` damages the first job.
std::vector<std::vector<std::uint8_t>> three_jobs(const std::string& target, LinkFault fault) {
  PilLink link(options_for(target));
  pil::Frame cfg;
  pil::Writer w(cfg);
  w.u(1, 1);     // approach B
  w.u(1, 1);     // exact Q_d
  w.u(2000, 2);  // initial PWM code
  link.request(pil::Type::kConfig, cfg);
  pil::Frame job;
  pil::Writer jw(job);
  jw.u(41'000, 4);  // sample at 41 ms
  jw.u(50'000, 4);  // next actuation at 50 ms
  jw.s(2300, 2);    // ADC code
  jw.s(2048, 2);    // set-point code
  std::vector<std::vector<std::uint8_t>> replies;
  for (int k = 0; k < 3; ++k) {
    if (k == 0) link.inject(fault);
    const pil::Frame r = link.request(pil::Type::kSample, job);
    replies.emplace_back(r.payload, r.payload + r.length);
  }
  EXPECT_EQ(link.resends(), fault == LinkFault::kNone ? 0U : 1U);
  return replies;
}

TEST_P(PilLinkTest, ALostReplyIsResentNotRerun) {
  // GIVEN three identical jobs, each moving the estimate on
  const auto clean = three_jobs(GetParam(), LinkFault::kNone);
  EXPECT_NE(clean[0], clean[1]);
  // WHEN the first job's reply is lost, or its request damaged, and the host resends
  // THEN every reply is the same as on a clean link: the firmware ran each job once
  EXPECT_EQ(three_jobs(GetParam(), LinkFault::kLoseReply), clean);
  EXPECT_EQ(three_jobs(GetParam(), LinkFault::kCorruptByte), clean);
  EXPECT_EQ(three_jobs(GetParam(), LinkFault::kDropByte), clean);
}

TEST_P(PilLinkTest, ReportsItsStackPeakWithinTheReservation) {
  PilLink link(options_for(GetParam()));
  expect_echo(link, 0);
  const int peak = link.stack_peak_bytes();
  EXPECT_GT(peak, 64);
  EXPECT_LT(peak, 6144);  // STACK_SIZE in firmware/app/mcu/oneshot_sections.ld
}

/// The firmware's answer to `request`: the PilError text, or "(ran)" when it was accepted.
std::string refusal(PilLink& link, pil::Type type, const pil::Frame& request) {
  try {
    link.request(type, request);
  } catch (const PilError& e) {
    return e.what();
  }
  return "(ran)";
}

TEST_P(PilLinkTest, ATruncatedRequestIsRefusedNotRunOnZeros) {
  PilLink link(options_for(GetParam()));
  pil::Frame job;
  pil::Writer w(job);
  w.u(41'000, 4);  // the sample instant only: the next actuation, ADC and set-point codes are missing
  EXPECT_NE(refusal(link, pil::Type::kSample, job).find("refused a malformed request"), std::string::npos);
}

TEST_P(PilLinkTest, AConfigWithAnUnknownApproachIsRefused) {
  PilLink link(options_for(GetParam()));
  pil::Frame cfg;
  pil::Writer w(cfg);
  w.u(7, 1);  // no approach H
  w.u(1, 1);
  w.u(2000, 2);
  EXPECT_NE(refusal(link, pil::Type::kConfig, cfg).find("refused a malformed request"), std::string::npos);
}

TEST_P(PilLinkTest, TheGeneratedCJobIsRefusedByAnImageWithoutIt) {
  // Approach 5 (the C99 job) exists on table images only; the generic image refuses it
  // instead of running another approach in its place.
  PilOptions o = options_for(GetParam());
  o.discretizer = "generic";
  PilLink link(o);
  pil::Frame cfg;
  pil::Writer w(cfg);
  w.u(pil::kCJobApproach, 1);
  w.u(1, 1);
  w.u(2000, 2);
  EXPECT_NE(refusal(link, pil::Type::kConfig, cfg).find("refused a malformed request"), std::string::npos);
}

INSTANTIATE_TEST_SUITE_P(Targets, PilLinkTest, ::testing::Values("cortex-m0", "cortex-m4f"),
                         [](const ::testing::TestParamInfo<std::string>& param_info) {
                           return std::string(param_info.param == "cortex-m0" ? "M0" : "M4F");
                         });

TEST(PilLink, MissingImageIsAClearError) {
  PilOptions o;
  o.firmware_dir = "/nonexistent/oneshot";
  try {
    PilLink link(o);
    FAIL() << "expected PilError";
  } catch (const PilError& e) {
    EXPECT_NE(std::string(e.what()).find("firmware image not found"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace oneshot::sim
