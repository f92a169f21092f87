/// @file plant_description_test.cpp
/// @brief Plant files: the reference parses; every bad input is refused with a message
///        that names the field.
#include <gtest/gtest.h>

#include "oneshot/design/plant_description.hpp"
#include "support/run_command.hpp"
#include "support/test_plants.hpp"

namespace oneshot::design {
namespace {

TEST(PlantDescription, ReferenceBoardIsTheBuiltInDefault) {
  const PlantDescription p = reference_plant();
  EXPECT_EQ(p.name, "flex-double-integrator");
  ASSERT_EQ(p.n(), 2U);
  EXPECT_EQ(p.m(), 1U);
  EXPECT_EQ(p.p(), 1U);
  EXPECT_DOUBLE_EQ(p.a(0, 1), -23.8);
  EXPECT_DOUBLE_EQ(p.b(1, 0), -23.8);
  EXPECT_EQ(p.period_us, 50000);
  EXPECT_DOUBLE_EQ(p.process_covariance(0, 0), 2e-7);
  EXPECT_DOUBLE_EQ(p.measurement_covariance(0, 0), 8e-5);
  EXPECT_EQ(p.table_granularity_us, 1000);
  EXPECT_EQ(p.table_range_us, 50000);
  EXPECT_EQ(p.states[1], "v2");
}

struct BadCase {
  const char* what;
  const char* pointer;  // JSON pointer to replace ("" value removes it)
  const char* value;
  const char* expected;  // substring of the message
};

void PrintTo(const BadCase& c, std::ostream* os) { *os << c.what; }

class BadPlant : public ::testing::TestWithParam<BadCase> {};

TEST_P(BadPlant, IsRefusedNamingTheField) {
  const BadCase c = GetParam();
  const std::string text = test::reference_with(c.pointer, c.value);
  try {
    parse_plant(text, "case.json");
    FAIL() << c.what << ": accepted";
  } catch (const PlantError& e) {
    EXPECT_NE(std::string(e.what()).find(c.expected), std::string::npos) << c.what << ": " << e.what();
    EXPECT_NE(std::string(e.what()).find("case.json"), std::string::npos) << e.what();
  }
}

INSTANTIATE_TEST_SUITE_P(
    Cases, BadPlant,
    ::testing::Values(
        BadCase{"A not square", "/A", "[[0, 1, 2], [0, 0, 1]]", "field 'A'"},
        BadCase{"A ragged", "/A", "[[0, 1], [0]]", "field 'A[1]'"},
        BadCase{"A empty", "/A", "[]", "field 'A'"},
        BadCase{"A entry not a number", "/A", "[[0, \"nan\"], [0, 0]]", "field 'A[0][1]': must be a number"},
        BadCase{"A entry null", "/A", "[[0, null], [0, 0]]", "field 'A[0][1]'"},
        BadCase{"too many states", "/A", "[[0,0,0,0,0],[0,0,0,0,0],[0,0,0,0,0],[0,0,0,0,0],[0,0,0,0,0]]", "field 'A'"},
        BadCase{"B wrong rows", "/B", "[[0], [1], [2]]", "field 'B'"},
        BadCase{"C wrong columns", "/C", "[[1, 0, 0]]", "field 'C'"},
        BadCase{"A missing", "/A", "", "field 'A': is missing"},
        BadCase{"unknown top-level field", "/noize", "1", "field 'noize': unknown field"},
        BadCase{"period zero", "/period_us", "0", "field 'period_us'"},
        BadCase{"period negative", "/period_us", "-50000", "field 'period_us'"},
        BadCase{"period not integer", "/period_us", "0.05", "field 'period_us': must be an integer"},
        BadCase{"R zero", "/noise/measurement_covariance", "[[0]]", "field 'noise.measurement_covariance'"},
        BadCase{"R negative", "/noise/measurement_covariance", "[[-8e-5]]", "field 'noise.measurement_covariance'"},
        BadCase{"R wrong shape", "/noise/measurement_covariance", "[[1, 0], [0, 1]]",
                "field 'noise.measurement_covariance': must be 1x1"},
        BadCase{"Qn all zero", "/noise/process_covariance", "[[0, 0], [0, 0]]", "field 'noise.process_covariance'"},
        BadCase{"Qn indefinite", "/noise/process_covariance", "[[2e-7, 0], [0, -2e-7]]",
                "field 'noise.process_covariance': must be positive semidefinite"},
        BadCase{"Qn not symmetric", "/noise/process_covariance", "[[2e-7, 1e-7], [0, 2e-7]]",
                "field 'noise.process_covariance': must be symmetric"},
        BadCase{"P0 singular", "/noise/initial_covariance", "[[1, 1], [1, 1]]", "field 'noise.initial_covariance'"},
        BadCase{"Q2c zero", "/cost/Q2c", "[[0]]", "field 'cost.Q2c'"},
        BadCase{"Q1c wrong shape", "/cost/Q1c", "[[1]]", "field 'cost.Q1c'"},
        BadCase{"granularity zero", "/table/granularity_us", "0", "field 'table.granularity_us'"},
        BadCase{"range not a multiple", "/table/range_us", "50500", "field 'table.range_us': must be a multiple"},
        BadCase{"max bytes zero", "/table/max_bytes", "0", "field 'table.max_bytes'"},
        BadCase{"PWM levels inverted", "/board/pwm_high_volts", "[-2.0]", "field 'board.pwm_high_volts[0]'"},
        BadCase{"PWM levels wrong length", "/board/pwm_low_volts", "[-1.65, 0]", "field 'board.pwm_low_volts'"},
        BadCase{"ADC bits", "/board/adc_bits", "40", "field 'board.adc_bits'"},
        BadCase{"state name not an identifier", "/states", "[\"v 1\", \"v2\"]", "field 'states[0]'"},
        BadCase{"duplicate state name", "/states", "[\"v\", \"v\"]", "field 'states[1]': duplicate"}),
    [](const ::testing::TestParamInfo<BadCase>& param_info) {
      std::string s = param_info.param.what;
      for (char& ch : s)
        if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
      return s;
    });

TEST(PlantDescription, InvalidJsonIsRefused) {
  EXPECT_THROW(parse_plant("{\"A\": [[0, 1e999]]}", "x.json"), PlantError);
  EXPECT_THROW(parse_plant("{\"A\": [[0, NaN]]}", "x.json"), PlantError);
  EXPECT_THROW(parse_plant("not json", "x.json"), PlantError);
  EXPECT_THROW(parse_plant("[1, 2]", "x.json"), PlantError);
}

TEST(PlantDescription, UnreadableFileIsRefused) {
  try {
    load_plant_file("/nonexistent/plant.json");
    FAIL();
  } catch (const PlantError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/plant.json: cannot read"), std::string::npos);
  }
  const std::string dir = test::write_temp_file("is_a_dir_probe", "");
  EXPECT_THROW(load_plant_file(dir.substr(0, dir.rfind('/'))), PlantError);  // a directory
}

TEST(PlantDescription, FileRoundTrip) {
  const std::string path = test::write_temp_file("reference.json", reference_plant_json());
  EXPECT_EQ(load_plant_file(path).a, reference_plant().a);
}

}  // namespace
}  // namespace oneshot::design
