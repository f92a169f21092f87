/// @file cpp_text_test.cpp
/// @brief A plant's name cannot put code into the generated header.
#include <gtest/gtest.h>

#include <sstream>

#include "oneshot/design/controller_synthesis.hpp"
#include "oneshot/design/cpp_text.hpp"
#include "oneshot/design/header_emitter.hpp"
#include "oneshot/design/plant_description.hpp"
#include "oneshot/design/structure_analysis.hpp"
#include "oneshot/design/table_builder.hpp"

namespace oneshot::design {
namespace {

/// The value of a C string literal with simple and octal escapes (enough for cpp_string_literal).
std::string unescape(const std::string& literal) {
  std::string out;
  for (std::size_t i = 1; i + 1 < literal.size(); ++i) {
    if (literal[i] != '\\') {
      out += literal[i];
    } else if (literal[i + 1] >= '0' && literal[i + 1] <= '7') {
      out += static_cast<char>(std::stoi(literal.substr(i + 1, 3), nullptr, 8));
      i += 3;
    } else {
      out += literal[++i];
    }
  }
  return out;
}

TEST(CppText, LiteralsRoundTripEveryByte) {
  std::string all;
  for (int c = 1; c < 256; ++c) all += static_cast<char>(c);
  const std::string lit = cpp_string_literal(all);
  EXPECT_EQ(unescape(lit), all);
  EXPECT_EQ(lit.find('\n'), std::string::npos);
  EXPECT_EQ(cpp_string_literal("a\"b\\"), "\"a\\\"b\\\\\"");
  EXPECT_EQ(cpp_string_literal("\n7"), "\"\\0127\"");  // octal escapes never swallow a following digit
}

TEST(HeaderEmitter, APlantNameCannotInjectCode) {
  PlantDescription plant = reference_plant();
  plant.name = "x\";\n#error injected by the name\nstatic int y = 1; // \\";
  plant.source = "file\\\n#error injected by the path";
  const DesignResult design = synthesize(plant);
  const PlantPatterns patterns = analyse_structure(plant, design);
  const auto tf = build_table<float>(plant, design, patterns);
  const auto td = build_table<double>(plant, design, patterns);
  const std::string header = emit_header(plant, design, patterns, tf, td, nullptr, nullptr, "no fixed point", "test");
  std::istringstream lines(header);
  std::string line;
  std::string name_line;
  while (std::getline(lines, line)) {
    EXPECT_NE(line.rfind("#error", 0), 0U) << line;
    EXPECT_NE(line.rfind("static int y", 0), 0U) << line;
    if (line.rfind("//", 0) == 0) {
      EXPECT_NE(line.back(), '\\') << "a comment continued onto the next line: " << line;
    }
    if (line.find("kPlantName[] = ") != std::string::npos) name_line = line;
  }
  ASSERT_FALSE(name_line.empty());
  const auto start = name_line.find('"');
  const auto end = name_line.rfind('"');
  EXPECT_EQ(unescape(name_line.substr(start, end - start + 1)), plant.name);
}

}  // namespace
}  // namespace oneshot::design
