/// @file param_names.hpp
/// @brief GoogleTest names of parameterized cases from their descriptions.
#pragma once

#include <cctype>
#include <string>

namespace oneshot::test {

/// `text` as a test-name suffix: every character that is not a letter or digit becomes '_'
/// ("nan:link=sc,rate=0.05" → "nan_link_sc_rate_0_05").
inline std::string param_name(std::string text) {
  for (char& ch : text)
    if (std::isalnum(static_cast<unsigned char>(ch)) == 0) ch = '_';
  return text;
}

}  // namespace oneshot::test
