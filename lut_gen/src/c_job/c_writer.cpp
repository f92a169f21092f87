/// @file c_writer.cpp
/// @brief Text helpers of the C job generator (see c_writer.hpp).
#include "c_job/c_writer.hpp"

#include <cstdio>
#include <cstring>
#include <stdexcept>

namespace oneshot::design::cjob {

std::string int_literal(long long v, int bits) {
  // Plain decimals are ints: safe in C99 only within the 16-bit int range.
  if (v >= -32767 && v <= 32767) return v < 0 ? "(" + std::to_string(v) + ")" : std::to_string(v);
  const char* macro = bits <= 32 && v >= -2147483647LL && v <= 2147483647LL ? "INT32_C" : "INT64_C";
  if (v < 0) {
    // −(x) keeps the literal positive; the most negative value is written as −max − 1.
    if (bits <= 32 && v == -2147483648LL) return "(-INT32_C(2147483647) - 1)";
    if (v == -9223372036854775807LL - 1) return "(-INT64_C(9223372036854775807) - 1)";
    return "(-" + std::string(macro) + "(" + std::to_string(-v) + "))";
  }
  return std::string(macro) + "(" + std::to_string(v) + ")";
}

std::string u32_literal(unsigned long long v) {
  if (v > 0xFFFFFFFFULL) throw std::logic_error("u32_literal: value does not fit 32 bits");
  return "UINT32_C(" + std::to_string(v) + ")";
}

std::string float_literal(float v) {
  char buf[48];
  std::snprintf(buf, sizeof buf, "%af", static_cast<double>(v));
  std::string s = buf;
  if (s[0] == '-') return "(" + s + ")";
  return s;
}

std::string comment_text(const std::string& s) {
  std::string out;
  for (char c : s) out += (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) ? '?' : c;
  return out;
}

std::string string_literal(const std::string& s) {
  std::string out;
  for (char c : s) {
    const auto u = static_cast<unsigned char>(c);
    if (c == '"' || c == '\\') {
      out += '\\';
      out += c;
    } else if (u < 0x20 || u >= 0x7f || c == '?') {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\%03o", u);  // octal: also avoids trigraphs
      out += buf;
    } else {
      out += c;
    }
  }
  return out;
}

void emit_range_split(CodeWriter& w, const std::string& decl, std::uint32_t range_us, std::uint32_t max_tau_us,
                      int& divisions) {
  const std::string range = int_literal(range_us, 32);
  w.line(decl + "repeats = " + divide_by_constant("tau_us", range_us, max_tau_us, divisions) + ";");
  w.line(decl + "remainder = tau_us - repeats * " + range + ";");
  w.line("status = ONESHOT_JOB_STATUS_EXTENDED;");
  w.open("if (repeats > 4 || (repeats == 4 && remainder > 0)) {")
      .line("repeats = 4;")
      .line("remainder = 0;")
      .line("status = ONESHOT_JOB_STATUS_CLAMPED;")
      .close();
}

std::string divide_by_constant(const std::string& x, std::uint32_t d, std::uint32_t max_x, int& divisions) {
  if (d == 0) throw std::logic_error("divide_by_constant: division by zero");
  // Strip the power of two: floor(floor(x / 2^k) / d') = floor(x / d).
  int k = 0;
  std::uint32_t odd = d;
  while ((odd & 1U) == 0U) {
    odd >>= 1;
    ++k;
  }
  const std::string shifted = k == 0 ? "(uint32_t)(" + x + ")" : "((uint32_t)(" + x + ") >> " + std::to_string(k) + ")";
  if (odd == 1) return "(int32_t)" + shifted;
  const std::uint64_t max_s = max_x >> k;
  for (int s = 1; s < 32; ++s) {
    const std::uint64_t m = ((std::uint64_t{1} << s) + odd - 1) / odd;  // ceil(2^s / d')
    if (max_s * m > 0xFFFFFFFFULL) break;  // the product must stay within 32 bits
    bool exact = true;
    for (std::uint64_t v = 0; v <= max_s && exact; ++v) exact = ((v * m) >> s) == v / odd;
    if (exact) return "(int32_t)((" + shifted + " * " + u32_literal(m) + ") >> " + std::to_string(s) + ")";
  }
  ++divisions;
  return "(int32_t)((uint32_t)(" + x + ") / " + u32_literal(d) + ")";
}

std::uint32_t float_bits(float v) {
  std::uint32_t b = 0;
  std::memcpy(&b, &v, sizeof b);
  return b;
}

}  // namespace oneshot::design::cjob
