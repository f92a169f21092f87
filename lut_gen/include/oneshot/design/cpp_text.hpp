/// @file cpp_text.hpp
/// @brief Free text (a plant's name, a file name) placed safely into generated C and C++.
///
/// A name from a plant file is data: a quote, a backslash at the end of a `//` comment
/// (which splices the next line into it) or a line break must not turn into code in the
/// firmware build.
#pragma once

#include <string>

namespace oneshot::design {

/// `text` as a C/C++ string literal with its quotes: printable ASCII as is, `"` and `\`
/// escaped, every other byte as a three-digit octal escape (never swallows what follows).
std::string cpp_string_literal(const std::string& text);

/// `text` for a `//` comment: cpp_string_literal(text), which has no line break and does
/// not end with a backslash.
std::string cpp_comment_text(const std::string& text);

}  // namespace oneshot::design
