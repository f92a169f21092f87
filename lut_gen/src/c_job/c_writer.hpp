/// @file c_writer.hpp
/// @brief Text helpers of the C job generator: an indenting line writer, literals, and
///        exact division by a constant through a reciprocal multiplication.
#pragma once

#include <cstdint>
#include <sstream>
#include <string>

namespace oneshot::design::cjob {

/// Lines of C with two-space indentation.
class CodeWriter {
 public:
  /// One line at the current depth.
  CodeWriter& line(const std::string& text) {
    if (text.empty()) {
      out_ << "\n";
    } else {
      out_ << std::string(static_cast<std::size_t>(2 * depth_), ' ') << text << "\n";
    }
    return *this;
  }
  /// `text` then one level deeper (an opening brace line).
  CodeWriter& open(const std::string& text) {
    line(text);
    ++depth_;
    return *this;
  }
  /// `text` one level shallower, staying at this depth (e.g. "} else {").
  CodeWriter& middle(const std::string& text) {
    --depth_;
    line(text);
    ++depth_;
    return *this;
  }
  /// One level shallower, then `text` (a closing brace line).
  CodeWriter& close(const std::string& text = "}") {
    --depth_;
    return line(text);
  }
  /// Everything written.
  std::string str() const { return out_.str(); }

 private:
  std::ostringstream out_;
  int depth_ = 0;
};

/// A signed integer literal of the given width that is valid C99 on 16-bit-int targets.
std::string int_literal(long long v, int bits);
/// An unsigned 32-bit literal.
std::string u32_literal(unsigned long long v);
/// The IEEE single bits of v.
std::uint32_t float_bits(float v);
/// A float literal in hexadecimal (exact), e.g. 0x1.8p+1f.
std::string float_literal(float v);
/// Text safe inside a // comment (control characters replaced).
std::string comment_text(const std::string& s);
/// A C string literal body (quotes, backslashes and non-printables escaped).
std::string string_literal(const std::string& s);

/// floor(x / d) for 0 ≤ x ≤ max_x as a C expression over the int32 expression `x`:
/// a power-of-two shift and a 32-bit multiplication by a reciprocal whose exactness over
/// the whole domain is verified here, or a plain division (counted in `divisions`) when no
/// 32-bit reciprocal is exact on that domain.
std::string divide_by_constant(const std::string& x, std::uint32_t d, std::uint32_t max_x, int& divisions);

/// Emits the split of tau_us (> range_us) into whole ranges and a remainder, both discretizers'
/// OutOfRange::kExtend rule: repeats = floor(tau_us / range), remainder = tau_us − repeats·range,
/// status EXTENDED; more than 4 ranges clamp to exactly 4 (status CLAMPED). `decl` prefixes the
/// two assignments ("int32_t " to declare them there, "" when they are declared already).
void emit_range_split(CodeWriter& w, const std::string& decl, std::uint32_t range_us, std::uint32_t max_tau_us,
                      int& divisions);

}  // namespace oneshot::design::cjob
