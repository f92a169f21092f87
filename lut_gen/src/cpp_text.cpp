/// @file cpp_text.cpp
/// @brief Escaping for generated code (see cpp_text.hpp).
#include "oneshot/design/cpp_text.hpp"

namespace oneshot::design {

std::string cpp_string_literal(const std::string& text) {
  std::string out = "\"";
  for (const char c : text) {
    const auto u = static_cast<unsigned char>(c);
    if (c == '"' || c == '\\') {
      out += '\\';
      out += c;
    } else if (u >= 0x20 && u < 0x7F && c != '?') {  // '?' escaped too: no trigraph in older dialects
      out += c;
    } else {
      out += '\\';
      out += static_cast<char>('0' + ((u >> 6) & 7));
      out += static_cast<char>('0' + ((u >> 3) & 7));
      out += static_cast<char>('0' + (u & 7));
    }
  }
  return out + "\"";
}

std::string cpp_comment_text(const std::string& text) { return cpp_string_literal(text); }

}  // namespace oneshot::design
