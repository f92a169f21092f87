/// @file fault_spec_test.cpp
/// @brief The fault spec's text form: the brief's example parses to the expected clauses,
///        canonical text round-trips, and every malformed spec is refused naming the clause
///        and the key.
#include <gtest/gtest.h>

#include <string>

#include "oneshot/engine/fault_spec.hpp"
#include "oneshot/engine/json_fields.hpp"
#include "support/expect_error.hpp"

namespace oneshot::engine {
namespace {

using Kind = FaultClause::Kind;

TEST(FaultSpec, ParsesEveryKindWithItsKeys) {
  const FaultSpec s = parse_fault_spec(
      " nan:link=sensor,rate=0.05; flip:bits=3,rate=0.01;dup:rate=0.02; replay:age_ms=200,rate=0.01; "
      "forge_seq:at_s=2,jump=65536; restart:node=sensor,at_s=5 ");
  ASSERT_EQ(s.clauses.size(), 6u);
  EXPECT_EQ(s.clauses[0].kind, Kind::kNan);
  EXPECT_EQ(s.clauses[0].link, "sensor");
  EXPECT_EQ(s.clauses[0].rate, 0.05);
  EXPECT_FALSE(s.clauses[0].once);
  EXPECT_EQ(s.clauses[1].kind, Kind::kFlip);
  EXPECT_EQ(s.clauses[1].bits, 3u);
  EXPECT_TRUE(s.clauses[1].link.empty());  // every link
  EXPECT_EQ(s.clauses[2].kind, Kind::kDup);
  EXPECT_EQ(s.clauses[3].kind, Kind::kReplay);
  EXPECT_EQ(s.clauses[3].age, Duration{200'000'000});
  EXPECT_EQ(s.clauses[4].kind, Kind::kForgeSeq);
  EXPECT_TRUE(s.clauses[4].once);
  EXPECT_EQ(s.clauses[4].at_s, 2.0);
  EXPECT_EQ(s.clauses[4].jump, 65536u);
  EXPECT_EQ(s.clauses[5].kind, Kind::kRestart);
  EXPECT_EQ(s.clauses[5].node, "sensor");
  EXPECT_EQ(s.clauses[5].at_s, 5.0);
  // Defaults: one bit, 200 ms, a jump of 2^31 − 2^16.
  const FaultSpec d = parse_fault_spec("flip:rate=1;replay:rate=1;forge_seq:rate=1");
  EXPECT_EQ(d.clauses[0].bits, 1u);
  EXPECT_EQ(d.clauses[1].age, Duration{200'000'000});
  EXPECT_EQ(d.clauses[2].jump, (1u << 31) - (1u << 16));
  // Canonical text parses back to the same clause.
  for (const FaultClause& c : s.clauses) {
    const FaultSpec back = parse_fault_spec(to_text(c));
    ASSERT_EQ(back.clauses.size(), 1u) << to_text(c);
    EXPECT_EQ(to_text(back.clauses[0]), to_text(c));
  }
  EXPECT_TRUE(parse_fault_spec("").empty());
  EXPECT_TRUE(parse_fault_spec("  ").empty());
}

/// The spec is refused and the message contains every one of `parts`.
void expect_refused(const std::string& spec, std::initializer_list<const char*> parts) {
  SCOPED_TRACE(spec);
  test::expect_error_naming<InputError>([&] { (void)parse_fault_spec(spec); }, parts);
}

TEST(FaultSpec, RefusesMalformedSpecsNamingClauseAndKey) {
  expect_refused("drop:rate=0.1", {"clause 1", "unknown fault 'drop'"});
  expect_refused("dup:rate=0.1;nan:ratio=0.1", {"clause 2 (nan)", "unknown key 'ratio'", "link, rate, at_s"});
  expect_refused("dup:rate=0.1,rate=0.2", {"key 'rate'", "twice"});
  expect_refused("dup:rate=1.5", {"key 'rate'", "out of range"});
  expect_refused("dup:rate=-0.1", {"key 'rate'", "out of range"});
  expect_refused("dup:rate=nan", {"key 'rate'", "not a number"});
  expect_refused("dup:rate=0.1x", {"key 'rate'", "not a number"});
  expect_refused("flip:rate=0.1,bits=0", {"key 'bits'", "out of range"});
  expect_refused("flip:rate=0.1,bits=65", {"key 'bits'", "out of range"});
  expect_refused("flip:rate=0.1,bits=1.5", {"key 'bits'", "whole"});
  expect_refused("replay:rate=0.1,age_ms=0", {"key 'age_ms'", "out of range"});
  expect_refused("forge_seq:at_s=-1", {"key 'at_s'", "out of range"});
  expect_refused("forge_seq:at_s=1,jump=0", {"key 'jump'", "out of range"});
  expect_refused("dup", {"clause 1 (dup)", "never fires"});
  expect_refused("dup:rate=0", {"never fires"});
  expect_refused("restart:at_s=1", {"key 'node' is required"});
  expect_refused("restart:node=sensor", {"key 'at_s' is required"});
  expect_refused("restart:node=sensor,at_s=1,rate=0.1", {"unknown key 'rate'"});
  expect_refused("nan:node=sensor,rate=0.1", {"unknown key 'node'"});
  expect_refused("dup:bits=2,rate=0.1", {"unknown key 'bits'"});
  expect_refused("dup:rate=0.1;", {"clause 2", "empty"});
  expect_refused(";dup:rate=0.1", {"clause 1", "empty"});
  expect_refused("dup:rate=0.1,", {"trailing ','"});
  expect_refused("dup:", {"without any key"});
  expect_refused("dup:rate", {"not key=value"});
  expect_refused("dup:link=a b,rate=0.1", {"not a link name"});
}

}  // namespace
}  // namespace oneshot::engine
