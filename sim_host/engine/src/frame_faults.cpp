/// @file frame_faults.cpp
/// @brief Frame faults of a link (see frame_faults.hpp).
#include "oneshot/engine/frame_faults.hpp"

#include <algorithm>

#include "oneshot/crc16.hpp"

#include "oneshot/engine/json_fields.hpp"

namespace oneshot::engine {

namespace {
/// Rewrites the CRC that ends `bytes` (when the layout has one) after a fault that models a
/// wrong sender rather than a corrupted transfer.
void reseal(const FrameLayout& layout, std::vector<std::uint8_t>& bytes) {
  if (layout.crc_bytes != 2 || bytes.size() < 2) return;
  const std::size_t n = bytes.size() - 2;
  const std::uint16_t crc = crc16_ccitt_false(bytes.data(), n);
  bytes[n] = static_cast<std::uint8_t>(crc & 0xFFU);
  bytes[n + 1] = static_cast<std::uint8_t>(crc >> 8);
}
}  // namespace

FaultCounters& FaultCounters::operator+=(const FaultCounters& o) {
  nan += o.nan;
  flip += o.flip;
  dup += o.dup;
  replay += o.replay;
  forge_seq += o.forge_seq;
  restart += o.restart;
  skipped += o.skipped;
  return *this;
}

void FaultCounters::count(FaultClause::Kind k) {
  switch (k) {
    case FaultClause::Kind::kNan: ++nan; break;
    case FaultClause::Kind::kFlip: ++flip; break;
    case FaultClause::Kind::kDup: ++dup; break;
    case FaultClause::Kind::kReplay: ++replay; break;
    case FaultClause::Kind::kForgeSeq: ++forge_seq; break;
    case FaultClause::Kind::kRestart: ++restart; break;
  }
}

LinkFaults::LinkFaults(const FaultSpec& spec, const std::string& link, const FrameLayout& layout, std::uint64_t seed)
    : layout_(layout) {
  for (std::size_t i = 0; i < spec.clauses.size(); ++i) {
    const FaultClause& c = spec.clauses[i];
    if (!is_frame_fault(c.kind) || (!c.link.empty() && c.link != link)) continue;
    const std::string base = "fault/" + std::to_string(i + 1) + "/" + kind_name(c.kind) + "/" + link;
    active_.push_back(Active{c, RandomStream(seed, base + "/hit"), RandomStream(seed, base + "/pick"), false});
    if (c.kind == FaultClause::Kind::kReplay) keep_ = std::max(keep_, c.age);
  }
}

void LinkFaults::apply(SimTime sent, std::vector<std::uint8_t>& bytes, std::vector<std::vector<std::uint8_t>>& extra) {
  for (Active& a : active_) {
    const bool by_rate = a.hit.uniform01() < a.clause.rate;  // one draw per frame, always
    bool hit = by_rate;
    if (a.clause.once && !a.fired && sent >= from_seconds(a.clause.at_s, "at_s")) {
      a.fired = true;
      hit = true;
    }
    if (!hit) continue;
    if (act(a, sent, bytes, extra)) {
      counters_.count(a.clause.kind);
    } else {
      ++counters_.skipped;
    }
  }
  if (keep_ > Duration{0}) {
    history_.emplace_back(sent, bytes);
    while (history_.size() > 1 && history_[1].first <= sent - keep_) history_.pop_front();
  }
}

bool LinkFaults::act(Active& a, SimTime sent, std::vector<std::uint8_t>& bytes, std::vector<std::vector<std::uint8_t>>& extra) {
  const FaultClause& c = a.clause;
  switch (c.kind) {
    case FaultClause::Kind::kNan: {
      const std::size_t w = layout_.value_bytes;
      const std::size_t end = bytes.size() - std::min(bytes.size(), layout_.crc_bytes);
      if ((w != 4 && w != 8) || end < layout_.value_offset + w) return false;
      const std::size_t slots = (end - layout_.value_offset) / w;
      const auto slot = static_cast<std::size_t>(a.pick.uniform_int(0, static_cast<std::int64_t>(slots) - 1));
      // Quiet NaN, little-endian: 0x7FF8000000000000 (binary64) or 0x7FC00000 (binary32).
      std::uint8_t* p = bytes.data() + layout_.value_offset + slot * w;
      std::fill(p, p + w, std::uint8_t{0});
      p[w - 1] = 0x7F;
      p[w - 2] = w == 8 ? 0xF8 : 0xC0;
      reseal(layout_, bytes);  // a NaN its sender computed: a valid frame, the receiver's finite check
      return true;
    }
    case FaultClause::Kind::kFlip: {
      const std::size_t nbits = bytes.size() * 8;
      if (nbits == 0) return false;
      const std::size_t n = std::min<std::size_t>(c.bits, nbits);
      std::vector<std::size_t> chosen;
      while (chosen.size() < n) {  // n distinct positions (rejection)
        const auto b = static_cast<std::size_t>(a.pick.uniform_int(0, static_cast<std::int64_t>(nbits) - 1));
        if (std::find(chosen.begin(), chosen.end(), b) == chosen.end()) chosen.push_back(b);
      }
      for (std::size_t b : chosen) bytes[b / 8] = static_cast<std::uint8_t>(bytes[b / 8] ^ (1u << (b % 8)));
      return true;
    }
    case FaultClause::Kind::kForgeSeq: {
      const std::size_t w = layout_.seq_bytes;
      if (w == 0 || w > 8 || bytes.size() < layout_.seq_offset + w) return false;
      std::uint8_t* p = bytes.data() + layout_.seq_offset;
      std::uint64_t seq = 0;
      for (std::size_t i = 0; i < w; ++i) seq |= std::uint64_t{p[i]} << (8 * i);
      seq += c.jump;  // modulo 2^(8w): the bytes below keep the low ones
      for (std::size_t i = 0; i < w; ++i) p[i] = static_cast<std::uint8_t>(seq >> (8 * i));
      reseal(layout_, bytes);  // a forger writes a valid frame: the sequence window catches it
      return true;
    }
    case FaultClause::Kind::kDup:
      extra.push_back(bytes);
      return true;
    case FaultClause::Kind::kReplay: {
      // The newest frame sent at least `age` ago.
      for (auto it = history_.rbegin(); it != history_.rend(); ++it) {
        if (it->first <= sent - c.age) {
          extra.push_back(it->second);
          return true;
        }
      }
      return false;
    }
    case FaultClause::Kind::kRestart:
      break;
  }
  return false;
}

void check_fault_targets(const FaultSpec& spec, const std::vector<std::string>& links, const std::vector<std::string>& nodes) {
  const auto list = [](const std::vector<std::string>& v) {
    std::string s;
    for (const auto& n : v) s += (s.empty() ? "" : ", ") + n;
    return s.empty() ? std::string("none") : s;
  };
  for (std::size_t i = 0; i < spec.clauses.size(); ++i) {
    const FaultClause& c = spec.clauses[i];
    const std::string where = "fault clause " + std::to_string(i + 1) + " (" + kind_name(c.kind) + ")";
    if (!c.link.empty() && std::find(links.begin(), links.end(), c.link) == links.end()) {
      throw InputError(where + ": no link '" + c.link + "' in this run (" + list(links) + ")");
    }
    if (!c.node.empty() && std::find(nodes.begin(), nodes.end(), c.node) == nodes.end()) {
      throw InputError(where + ": no restartable node '" + c.node + "' in this run (" + list(nodes) + ")");
    }
  }
}

std::vector<SimTime> restart_instants(const FaultSpec& spec, const std::string& node) {
  std::vector<SimTime> out;
  for (const FaultClause& c : spec.clauses)
    if (c.kind == FaultClause::Kind::kRestart && c.node == node) out.push_back(from_seconds(c.at_s, "at_s"));
  return out;
}

}  // namespace oneshot::engine
