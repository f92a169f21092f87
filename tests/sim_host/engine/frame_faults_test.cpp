/// @file frame_faults_test.cpp
/// @brief Each frame fault's effect on a stream of frames (fixed seeds): NaN in one value
///        slot, exactly `bits` inverted bits, the sequence number moved by `jump`, the
///        duplicate and the replayed frame, hits at the rate (binomial, |z| < 3.29), the same
///        bytes for the same seed, clauses that never move one another; on the network:
///        the extra frames arrive right after theirs, restarts run their hook at their
///        instant, and unknown targets are refused; with a CRC in the layout, nan and
///        forge_seq rewrite it and flip does not. The studies' sequenced frames
///        (sequenced_frame.hpp): their CRC-16 against a bitwise one written here, every 1-bit
///        flip of both sizes the studies send and every 2-bit flip of the 1-value frame
///        decoded as corrupt, a wrong size as malformed, nan and forge_seq still decoded.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include "oneshot/crc16.hpp"
#include "oneshot/engine/frame_faults.hpp"
#include "oneshot/engine/json_fields.hpp"
#include "oneshot/engine/kernel.hpp"
#include "oneshot/engine/network.hpp"
#include "oneshot/engine/sequenced_frame.hpp"

namespace oneshot::engine {
namespace {

using Bytes = std::vector<std::uint8_t>;

/// Layout of the test frames: seq (4) | stamp (4) | doubles.
FrameLayout layout() { return FrameLayout{0, 4, 8, 8}; }

/// Frame k: seq k, stamp 0, values k + 0.5 and −k.
Bytes frame(std::uint32_t k) {
  Bytes b(24, 0);
  for (int i = 0; i < 4; ++i) b[static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(k >> (8 * i));
  const double v[2] = {k + 0.5, -static_cast<double>(k)};
  std::memcpy(b.data() + 8, v, 16);
  return b;
}

double value(const Bytes& b, std::size_t i) {
  double v = 0;
  std::memcpy(&v, b.data() + 8 + 8 * i, 8);
  return v;
}

/// Runs frames 0..n−1 sent every 10 ms through the faults; returns what leaves them.
std::vector<Bytes> stream(LinkFaults& f, std::uint32_t n) {
  std::vector<Bytes> out;
  for (std::uint32_t k = 0; k < n; ++k) {
    Bytes b = frame(k);
    std::vector<Bytes> extra;
    f.apply(SimTime{std::int64_t{k} * 10'000'000}, b, extra);
    out.push_back(b);
    for (auto& e : extra) out.push_back(e);
  }
  return out;
}

/// True when the last two bytes of `b` are the CRC-16/CCITT-FALSE of the bytes before them.
bool crc_ok(const Bytes& b) {
  const std::uint16_t c = crc16_ccitt_false(b.data(), b.size() - 2);
  return b[b.size() - 2] == (c & 0xFFU) && b[b.size() - 1] == (c >> 8);
}

TEST(FrameFaults, WithACrcNanAndForgedSequenceAreResealedAndFlipsAreNot) {
  const FrameLayout crc_layout{0, 4, 8, 8, 2};
  for (const char* spec : {"nan:rate=1", "forge_seq:rate=1", "flip:rate=1", "flip:bits=2,rate=1", "dup:rate=1"}) {
    LinkFaults f(parse_fault_spec(spec), "sc", crc_layout, 3);
    const bool flip = std::string(spec).rfind("flip", 0) == 0;
    for (std::uint32_t k = 0; k < 50; ++k) {
      Bytes b = frame(k);
      b.resize(26);
      const std::uint16_t c = crc16_ccitt_false(b.data(), 24);
      b[24] = static_cast<std::uint8_t>(c & 0xFFU);
      b[25] = static_cast<std::uint8_t>(c >> 8);
      const Bytes sent = b;
      std::vector<Bytes> extra;
      f.apply(SimTime{std::int64_t{k} * 10'000'000}, b, extra);
      EXPECT_EQ(crc_ok(b), !flip) << spec << " frame " << k;  // a transfer error breaks it, a wrong sender seals it
      if (std::string(spec) == "nan:rate=1") {
        EXPECT_TRUE(std::isnan(value(b, 0)) || std::isnan(value(b, 1))) << k;  // never the CRC's bytes
      }
      if (std::string(spec) == "dup:rate=1") {
        EXPECT_EQ(b, sent);
      }
    }
  }
}

TEST(FrameFaults, NanOnceTurnsOneValueOfOneFrameNaN) {
  LinkFaults f(parse_fault_spec("nan:link=sc,at_s=0.1"), "sc", layout(), 1);
  const auto out = stream(f, 30);
  ASSERT_EQ(out.size(), 30u);
  for (std::uint32_t k = 0; k < 30; ++k) {
    const bool nan = std::isnan(value(out[k], 0)) || std::isnan(value(out[k], 1));
    EXPECT_EQ(nan, k == 10) << k;  // the first frame at or after 100 ms
    EXPECT_EQ(std::memcmp(out[k].data(), frame(k).data(), 8), 0);  // header untouched
  }
  EXPECT_EQ(f.counters().nan, 1u);
  // Another link is not touched by a clause naming "sc".
  LinkFaults other(parse_fault_spec("nan:link=sc,at_s=0.1"), "ca", layout(), 1);
  EXPECT_TRUE(other.empty());
}

TEST(FrameFaults, FlipInvertsExactlyTheGivenBitsAndForgeMovesTheSequence) {
  LinkFaults flip(parse_fault_spec("flip:bits=5,rate=1"), "x", layout(), 2);
  const auto out = stream(flip, 50);
  for (std::uint32_t k = 0; k < 50; ++k) {
    const Bytes clean = frame(k);
    int diff = 0;
    for (std::size_t i = 0; i < clean.size(); ++i) diff += __builtin_popcount(static_cast<unsigned>(clean[i] ^ out[k][i]));
    EXPECT_EQ(diff, 5) << k;
  }
  EXPECT_EQ(flip.counters().flip, 50u);
  LinkFaults forge(parse_fault_spec("forge_seq:at_s=0.05"), "x", layout(), 3);
  const auto f = stream(forge, 10);
  for (std::uint32_t k = 0; k < 10; ++k) {
    std::uint32_t seq = 0;
    std::memcpy(&seq, f[k].data(), 4);
    EXPECT_EQ(seq, k == 5 ? k + 0x7FFF0000u : k);
    EXPECT_EQ(value(f[k], 0), k + 0.5);
  }
  // Wraps modulo 2^32.
  LinkFaults wrap(parse_fault_spec("forge_seq:at_s=0,jump=4294967295"), "x", layout(), 3);
  std::uint32_t seq = 0;
  const auto w = stream(wrap, 2);
  std::memcpy(&seq, w[1].data(), 4);
  EXPECT_EQ(seq, 1u);
  std::memcpy(&seq, w[0].data(), 4);
  EXPECT_EQ(seq, 0xFFFFFFFFu);
}

TEST(FrameFaults, DuplicateAndReplayAddTheRightFrames) {
  LinkFaults dup(parse_fault_spec("dup:at_s=0.02"), "x", layout(), 4);
  const auto d = stream(dup, 5);
  ASSERT_EQ(d.size(), 6u);
  EXPECT_EQ(d[2], frame(2));
  EXPECT_EQ(d[3], frame(2));  // the copy right after it
  EXPECT_EQ(d[4], frame(3));
  // Replay of age 45 ms with frames every 10 ms: at t = 100 ms the newest frame sent at or
  // before 55 ms is frame 5; before t = 45 ms nothing is old enough (skipped).
  LinkFaults rep(parse_fault_spec("replay:age_ms=45,at_s=0.1;replay:age_ms=45,at_s=0.01"), "x", layout(), 5);
  const auto r = stream(rep, 12);
  ASSERT_EQ(r.size(), 13u);
  EXPECT_EQ(r[10], frame(10));
  EXPECT_EQ(r[11], frame(5));
  EXPECT_EQ(rep.counters().replay, 1u);
  EXPECT_EQ(rep.counters().skipped, 1u);
}

TEST(FrameFaults, HitsAtTheRateSameBytesForTheSameSeedClausesIndependent) {
  const std::uint32_t n = 20000;
  LinkFaults a(parse_fault_spec("dup:rate=0.1"), "x", layout(), 7);
  const double hits = static_cast<double>(stream(a, n).size() - n);
  EXPECT_LT(std::fabs(hits - n * 0.1) / std::sqrt(n * 0.1 * 0.9), 3.29);
  LinkFaults b1(parse_fault_spec("nan:rate=0.3;flip:rate=0.3"), "x", layout(), 9);
  LinkFaults b2(parse_fault_spec("nan:rate=0.3;flip:rate=0.3"), "x", layout(), 9);
  LinkFaults b3(parse_fault_spec("nan:rate=0.3;flip:rate=0.3"), "x", layout(), 10);
  const auto s1 = stream(b1, 200);
  EXPECT_EQ(s1, stream(b2, 200));
  EXPECT_NE(s1, stream(b3, 200));
  // The NaN hits of clause 1 do not move when clause 2 (dup) is added or changes rate.
  const auto nan_frames = [&](const char* spec) {
    LinkFaults f(parse_fault_spec(spec), "x", layout(), 11);
    std::vector<std::uint32_t> ks;
    for (std::uint32_t k = 0; k < 500; ++k) {
      Bytes b = frame(k);
      std::vector<Bytes> extra;
      f.apply(SimTime{std::int64_t{k} * 1'000'000}, b, extra);
      if (std::isnan(value(b, 0)) || std::isnan(value(b, 1))) ks.push_back(k);
    }
    return ks;
  };
  const auto alone = nan_frames("nan:rate=0.1");
  EXPECT_FALSE(alone.empty());
  EXPECT_EQ(alone, nan_frames("nan:rate=0.1;dup:rate=0.5"));
  EXPECT_EQ(alone, nan_frames("nan:rate=0.1;dup:rate=0.9"));
  // A frame without values or sequence number: the hit is counted as skipped.
  LinkFaults none(parse_fault_spec("nan:rate=1;forge_seq:rate=1"), "x", FrameLayout{0, 0, 0, 0}, 1);
  const auto u = stream(none, 3);
  EXPECT_EQ(u[1], frame(1));
  EXPECT_EQ(none.counters().skipped, 6u);
}

TEST(FrameFaults, NetworkDeliversExtrasAfterTheFrameAndRunsRestartHooks) {
  Kernel kernel(1);
  Network net(kernel);
  net.set_faults(parse_fault_spec("dup:link=ab,at_s=0;restart:node=b,at_s=0.5"));
  std::vector<Bytes> got;
  net.add_node(1, "a", Duration{0}, nullptr);
  net.add_node(2, "b", Duration{0}, [&]() {
    while (!net.node(2).interface.inbox.empty()) {
      got.push_back(net.node(2).interface.inbox.front().bytes);
      net.node(2).interface.inbox.pop_front();
    }
  });
  LinkConfig ab;
  ab.name = "ab";
  ab.delay.kind = DelayModel::Kind::kConstant;
  ab.delay.constant = from_us(100);
  net.route(1, 2, net.add_link(ab));
  int restarted = 0;
  SimTime restarted_at{0};
  net.arm_faults({{"b", [&]() {
                     ++restarted;
                     restarted_at = kernel.now();
                   }}});
  const HandlerId send = kernel.add_handler("send", [&](std::uint64_t k) {
    net.run_node(1, [&]() {
      host::HostNetworkState& s = net.node(1).interface;
      s.outbox.push_back(host::Frame{1, 2, frame(static_cast<std::uint32_t>(k))});
    });
  });
  for (std::uint64_t k = 0; k < 3; ++k) kernel.schedule(SimTime{static_cast<std::int64_t>(k) * 1'000'000}, EventClass::kSample, send, k);
  kernel.run_until(SimTime{1'000'000'000});
  ASSERT_EQ(got.size(), 4u);
  EXPECT_EQ(got[0], frame(0));
  EXPECT_EQ(got[1], frame(0));
  EXPECT_EQ(got[2], frame(1));
  EXPECT_EQ(restarted, 1);
  EXPECT_EQ(restarted_at, SimTime{500'000'000});
  EXPECT_EQ(net.fault_counters().dup, 1u);
  EXPECT_EQ(net.fault_counters().restart, 1u);
  // Unknown targets are refused, naming the clause and listing the names.
  EXPECT_THROW(check_fault_targets(parse_fault_spec("dup:link=zz,rate=0.1"), {"ab"}, {}), InputError);
  EXPECT_NO_THROW(check_fault_targets(parse_fault_spec("dup:link=ab,rate=0.1;restart:node=b,at_s=1"), {"ab"}, {"b"}));
  Kernel k3(1);
  Network n3(k3);
  n3.set_faults(parse_fault_spec("restart:node=c,at_s=1"));
  try {
    n3.arm_faults({{"b", []() {}}});
    ADD_FAILURE() << "accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("no restartable node 'c' in this run (b)"), std::string::npos) << e.what();
  }
}

/// CRC-16/CCITT-FALSE bit by bit, as its definition reads (poly 0x1021, init 0xFFFF, MSB first).
std::uint16_t bitwise_crc(const std::uint8_t* p, std::size_t n) {
  unsigned crc = 0xFFFF;
  for (std::size_t i = 0; i < n; ++i) {
    crc ^= static_cast<unsigned>(p[i]) << 8;
    for (int b = 0; b < 8; ++b) crc = ((crc & 0x8000U) != 0U ? (crc << 1) ^ 0x1021U : crc << 1) & 0xFFFFU;
  }
  return static_cast<std::uint16_t>(crc);
}

/// The sizes the studies send: one sample (dropping, sod, petc's sc) and petc's packet of 201 inputs (ca).
constexpr std::size_t kStudyValueCounts[] = {1, 201};

/// A sequenced frame of `n` values: seq 0x8123'4567, values with varied bits.
Bytes sequenced(std::size_t n) {
  std::vector<double> v(n);
  for (std::size_t i = 0; i < n; ++i) v[i] = (i % 2 == 0 ? 1 : -1) * (0.37 + 1.5e-3 * static_cast<double>(i * i));
  return encode_sequenced_frame(0x8123'4567U, v.data(), n);
}

TEST(SequencedFrame, EndsInTheCrc16OfItsBytesAndDecodesToWhatWasSent) {
  for (std::size_t n : kStudyValueCounts) {
    const Bytes b = sequenced(n);
    ASSERT_EQ(b.size(), 4 + 8 * n + 2);
    const std::uint16_t c = bitwise_crc(b.data(), b.size() - 2);
    EXPECT_EQ(b[b.size() - 2], c & 0xFFU) << n;  // low byte first
    EXPECT_EQ(b[b.size() - 1], c >> 8) << n;
    std::uint32_t seq = 0;
    std::vector<double> v(n);
    ASSERT_EQ(decode_sequenced_frame(b, seq, v.data(), n), SequencedFrameStatus::kOk) << n;
    EXPECT_EQ(seq, 0x8123'4567U);
    for (std::size_t i = 0; i < n; ++i) EXPECT_EQ(v[i], (i % 2 == 0 ? 1 : -1) * (0.37 + 1.5e-3 * static_cast<double>(i * i)));
  }
  const double y = 2.5;
  EXPECT_EQ(bitwise_crc(reinterpret_cast<const std::uint8_t*>("123456789"), 9), 0x29B1);  // the oracle's check value
  EXPECT_LT(static_cast<int>(SequencedFrameStatus::kOk), static_cast<int>(SequencedFrameStatus::kCorrupt));
  EXPECT_LT(static_cast<int>(SequencedFrameStatus::kCorrupt), static_cast<int>(SequencedFrameStatus::kMalformed));
  EXPECT_EQ(encode_sequenced_frame(7, &y, 1).size(), sequenced_frame_bytes(1));
}

TEST(SequencedFrame, EveryOneBitFlipIsCorruptAndWritesNothing) {
  for (std::size_t n : kStudyValueCounts) {
    const Bytes sent = sequenced(n);
    std::vector<double> v(n, 0.0);
    for (std::size_t bit = 0; bit < sent.size() * 8; ++bit) {
      Bytes b = sent;
      b[bit / 8] = static_cast<std::uint8_t>(b[bit / 8] ^ (1U << (bit % 8)));
      std::uint32_t seq = 7;
      ASSERT_EQ(decode_sequenced_frame(b, seq, v.data(), n), SequencedFrameStatus::kCorrupt) << n << " values, bit " << bit;
      ASSERT_EQ(seq, 7U);
    }
    for (double x : v) EXPECT_EQ(x, 0.0);
  }
}

TEST(SequencedFrame, EveryTwoBitFlipOfTheOneValueFrameIsCorrupt) {
  const Bytes sent = sequenced(1);
  const std::size_t bits = sent.size() * 8;
  std::size_t pairs = 0;
  for (std::size_t i = 0; i < bits; ++i)
    for (std::size_t j = i + 1; j < bits; ++j) {
      Bytes b = sent;
      b[i / 8] = static_cast<std::uint8_t>(b[i / 8] ^ (1U << (i % 8)));
      b[j / 8] = static_cast<std::uint8_t>(b[j / 8] ^ (1U << (j % 8)));
      std::uint32_t seq = 0;
      double y = 0;
      ASSERT_EQ(decode_sequenced_frame(b, seq, &y, 1), SequencedFrameStatus::kCorrupt) << "bits " << i << ", " << j;
      ++pairs;
    }
  EXPECT_EQ(pairs, bits * (bits - 1) / 2);
}

TEST(SequencedFrame, AWrongSizeIsMalformed) {
  for (std::size_t n : kStudyValueCounts) {
    std::vector<double> v(n);
    std::uint32_t seq = 0;
    Bytes b = sequenced(n);
    b.push_back(0);
    EXPECT_EQ(decode_sequenced_frame(b, seq, v.data(), n), SequencedFrameStatus::kMalformed) << n;
    b.resize(b.size() - 2);
    EXPECT_EQ(decode_sequenced_frame(b, seq, v.data(), n), SequencedFrameStatus::kMalformed) << n;
    EXPECT_EQ(decode_sequenced_frame(Bytes{}, seq, v.data(), n), SequencedFrameStatus::kMalformed) << n;
  }
}

TEST(SequencedFrame, ThroughLinkFaultsNanAndForgedSequenceDecodeAndFlipsAreCorrupt) {
  for (std::size_t n : kStudyValueCounts)
    for (const char* spec : {"nan:rate=1", "forge_seq:rate=1,jump=5", "flip:rate=1", "flip:bits=2,rate=1", "flip:bits=3,rate=1"}) {
      LinkFaults f(parse_fault_spec(spec), "sc", kSequencedFrameLayout, 9);
      const bool flip = std::string(spec).rfind("flip", 0) == 0;
      for (std::uint32_t k = 0; k < 40; ++k) {
        Bytes b = sequenced(n);
        std::vector<Bytes> extra;
        f.apply(SimTime{std::int64_t{k} * 10'000'000}, b, extra);
        std::uint32_t seq = 0;
        std::vector<double> v(n);
        const SequencedFrameStatus st = decode_sequenced_frame(b, seq, v.data(), n);
        if (flip) {
          EXPECT_EQ(st, SequencedFrameStatus::kCorrupt) << spec << ", " << n << " values, frame " << k;
          continue;
        }
        ASSERT_EQ(st, SequencedFrameStatus::kOk) << spec << ", " << n << " values, frame " << k;
        if (spec[0] == 'n') {
          std::size_t nans = 0;
          for (double x : v) nans += std::isnan(x) ? 1U : 0U;
          EXPECT_EQ(nans, 1U) << n;
          EXPECT_EQ(seq, 0x8123'4567U);
        } else {
          EXPECT_EQ(seq, 0x8123'4567U + 5U);
        }
      }
    }
}

}  // namespace
}  // namespace oneshot::engine
