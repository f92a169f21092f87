/// @file plant_description_test.cpp
/// @brief Plant files: the reference parses; every bad input is refused with a message
///        that names the field.
#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "oneshot/design/dense_ops.hpp"
#include "oneshot/design/plant_description.hpp"
#include "oneshot/design/zoh_inverse.hpp"
#include "support/run_command.hpp"
#include "support/test_plants.hpp"
#include "support/expect_error.hpp"
#include "support/param_names.hpp"

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
  EXPECT_DOUBLE_EQ(p.process_covariance_per_period(0, 0), 2e-7);
  EXPECT_EQ(p.process_intensity.rows, 0U);
  EXPECT_EQ(p.form, PlantForm::kContinuous);
  EXPECT_TRUE(p.has_board);
  EXPECT_TRUE(p.has_table);
  EXPECT_DOUBLE_EQ(p.measurement_covariance(0, 0), 8e-5);
  EXPECT_EQ(p.table_granularity_us, 1000);
  EXPECT_EQ(p.table_range_us, 50000);
  EXPECT_EQ(p.states[1], "v2");
}

struct BadCase {
  std::string what;
  std::string pointer;  // JSON pointer to replace ("" value removes it)
  std::string value;
  std::string expected;  // substring of the message
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
        BadCase{"too many states", "/A", std::string("[") + [] {
                  std::string rows;
                  for (int i = 0; i < 17; ++i) rows += std::string(i ? "," : "") + "[0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0]";
                  return rows;
                }() + "]", "field 'A': 17 states exceed the supported maximum of 16 (kMaxStates"},
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
        BadCase{"Qn all zero", "/noise/process_covariance_per_period", "[[0, 0], [0, 0]]",
                "field 'noise.process_covariance_per_period'"},
        BadCase{"Qn indefinite", "/noise/process_covariance_per_period", "[[2e-7, 0], [0, -2e-7]]",
                "field 'noise.process_covariance_per_period': must be positive semidefinite"},
        BadCase{"Qn not symmetric", "/noise/process_covariance_per_period", "[[2e-7, 1e-7], [0, 2e-7]]",
                "field 'noise.process_covariance_per_period': must be symmetric"},
        BadCase{"Qn missing", "/noise/process_covariance_per_period", "", "field 'noise.process_covariance_per_period': is missing"},
        BadCase{"old ambiguous key", "/noise/process_covariance", "[[2e-7, 0], [0, 2e-7]]",
                "field 'noise.process_covariance': ambiguous and no longer read: give noise.process_covariance_per_period"},
        BadCase{"intensity and per period", "/noise/process_intensity", "[[4e-6, 0], [0, 4e-6]]", "not both"},
        BadCase{"B_w wrong rows", "/B_w", "[[1], [2], [3]]", "field 'B_w'"},
        BadCase{"B_w without its noise", "/B_w", "[[0], [1]]", "field 'noise.disturbance_covariance_per_period'"},
        BadCase{"Phi in a continuous plant", "/Phi", "[[1, 0], [0, 1]]", "field 'Phi': belongs to the discrete form"},
        BadCase{"unknown form", "/form", "\"hybrid\"", "field 'form'"},
        BadCase{"cost forms mixed", "/cost/Q2", "[[1]]", "field 'cost.Q2': cannot be mixed"},
        BadCase{"tracked output unknown", "/tracked_outputs", "[\"v9\"]", "field 'tracked_outputs[0]'"},
        BadCase{"tracked outputs too many", "/tracked_outputs", "[\"v1\", \"v1\"]", "field 'tracked_outputs'"},
        BadCase{"board and actuator", "/actuator", "{\"u_min\": [-1], \"u_max\": [1]}", "field 'actuator'"},
        BadCase{"period 2^64 - 1 as written", "/period_us", "18446744073709551615",
                "field 'period_us': must be in [1, 60000000], got 18446744073709551615"},
        BadCase{"period 2^63 as written", "/period_us", "9223372036854775808", "got 9223372036854775808"},
        BadCase{"period not a multiple of the granularity", "/period_us", "50500",
                "field 'table.granularity_us': the period h = 50500 us is not a multiple of the granularity 1000 us"},
        BadCase{"table range below h", "/table/range_us", "20000",
                "field 'table.range_us': 20000 us is below the period h = 50000 us"},
        BadCase{"PWM frequency 1e-10", "/board/pwm_frequency_hz", "1e-10",
                "field 'board.pwm_frequency_hz': the PWM period 1/f"},
        BadCase{"PWM frequency just above the int64 overflow", "/board/pwm_frequency_hz", "1.1e-10",
                "longer than the control period"},
        BadCase{"PWM period longer than h", "/board/pwm_frequency_hz", "10",
                "the PWM period 1/f = 100000 us is longer than the control period h = 50000 us"},
        BadCase{"sub-nanosecond duty steps", "/board/pwm_duty_steps", "1000000",
                "field 'board.pwm_duty_steps': 1000000 duty steps at 20000 Hz give a duty step of 0.05 ns"},
        BadCase{"P0 singular", "/noise/initial_covariance", "[[1, 1], [1, 1]]", "field 'noise.initial_covariance'"},
        BadCase{"Q2c zero", "/cost/Q2c", "[[0]]", "field 'cost.Q2c'"},
        BadCase{"Q1c wrong shape", "/cost/Q1c", "[[1]]", "field 'cost.Q1c'"},
        BadCase{"granularity zero", "/table/granularity_us", "0", "field 'table.granularity_us'"},
        BadCase{"range not a multiple", "/table/range_us", "50500", "field 'table.range_us': must be a multiple"},
        BadCase{"max bytes zero", "/table/max_bytes", "0", "field 'table.max_bytes'"},
        BadCase{"PWM levels inverted", "/board/pwm_high_volts", "[-2.0]", "field 'board.pwm_high_volts[0]'"},
        BadCase{"PWM levels wrong length", "/board/pwm_low_volts", "[-1.65, 0]", "field 'board.pwm_low_volts'"},
        BadCase{"PWM level 1e308 V", "/board/pwm_high_volts", "[1e308]",
                "field 'board.pwm_high_volts[0]': 1e+308 V is outside the supported board range of +-1000 V"},
        BadCase{"PWM level -1e308 V", "/board/pwm_low_volts", "[-1e308]", "field 'board.pwm_low_volts[0]'"},
        BadCase{"ADC range 2 kV", "/board/adc_max_volts", "[2000]", "field 'board.adc_max_volts[0]'"},
        BadCase{"ADC bits", "/board/adc_bits", "40", "field 'board.adc_bits'"},
        BadCase{"state name not an identifier", "/states", "[\"v 1\", \"v2\"]", "field 'states[0]'"},
        BadCase{"duplicate state name", "/states", "[\"v\", \"v\"]", "field 'states[1]': duplicate"}),
    [](const ::testing::TestParamInfo<BadCase>& param_info) { return test::param_name(param_info.param.what); });

TEST(PlantDescription, InvalidJsonIsRefused) {
  EXPECT_THROW(parse_plant("{\"A\": [[0, 1e999]]}", "x.json"), PlantError);
  EXPECT_THROW(parse_plant("{\"A\": [[0, NaN]]}", "x.json"), PlantError);
  EXPECT_THROW(parse_plant("not json", "x.json"), PlantError);
  EXPECT_THROW(parse_plant("[1, 2]", "x.json"), PlantError);
}

TEST(PlantDescription, UnreadableFileIsRefused) {
  test::expect_error_naming<PlantError>([&] { load_plant_file("/nonexistent/plant.json"); },
                                        {"/nonexistent/plant.json: cannot read"});
  const std::string dir = test::write_temp_file("is_a_dir_probe", "");
  EXPECT_THROW(load_plant_file(dir.substr(0, dir.rfind('/'))), PlantError);  // a directory
}

std::string read_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream o;
  o << in.rdbuf();
  return o.str();
}

/// The message of the PlantError that parsing `text` throws ("" when it parses).
std::string error_of(const std::string& text) {
  return test::message_of<PlantError>([&] { parse_plant(text, "case.json"); }, "");
}

TEST(PlantDescription, DuplicateKeysAreRefusedNamingTheField) {
  std::string text = reference_plant_json();
  text.insert(text.find("\"period_us\""), "\"period_us\": 20000,\n  ");
  EXPECT_NE(error_of(text).find("field 'period_us': given twice"), std::string::npos) << error_of(text);
  std::string nested = reference_plant_json();
  nested.insert(nested.find("\"measurement_covariance\""), "\"measurement_covariance\": [[1]], ");
  EXPECT_NE(error_of(nested).find("field 'noise.measurement_covariance': given twice"), std::string::npos)
      << error_of(nested);
}

TEST(PlantDescription, HugePositiveSemidefiniteWeightIsAccepted) {
  // Its trace overflows to infinity: the check works on the matrix scaled by its largest entry.
  EXPECT_EQ(error_of(test::reference_with("/cost/Q1c", "[[1.5e308, 0], [0, 1.5e308]]")), "");
  EXPECT_NE(error_of(test::reference_with("/cost/Q1c", "[[1.5e308, 0], [0, -1.5e308]]")), "");
}

TEST(PlantDescription, NonFiniteNumbersAreRefused) {
  std::string text = reference_plant_json();
  text.replace(text.find("-23.8"), 5, "1e999");
  const std::string e = error_of(text);
  EXPECT_NE(e.find("1e999"), std::string::npos) << e;  // nlohmann refuses the overflow while parsing
}

TEST(PlantDescription, DevicesDirectoriesAndHugeFilesAreRefusedWithoutReadingThem) {
  // /dev/zero would be read until memory runs out
  test::expect_error_naming<PlantError>([&] { load_plant_file("/dev/zero"); }, {"/dev/zero: is not a regular file"});
  const std::string probe = test::write_temp_file("dir_probe.json", "{}");
  const std::string dir = probe.substr(0, probe.rfind('/'));
  const std::string what = test::expect_error_naming<PlantError>([&] { load_plant_file(dir); }, {"is a directory"});
  EXPECT_EQ(what.find("not valid JSON"), std::string::npos) << what;
  const std::string big = test::write_temp_file("big.json", reference_plant_json() + std::string(1u << 20, ' '));
  test::expect_error_naming<PlantError>([&] { load_plant_file(big); }, {"more than the limit of 1048576"});
}

const char* const kDiscrete = R"({"form": "discrete", "Phi": [[1.25, 1, 0], [0, 0.9, 7], [0, 0, 0.6]],
  "Gamma": [[2.2], [1], [0.1]], "C": [[1, 0, 2]], "period_us": 10000,
  "cost": {"Q1": [[1, 0, 0], [0, 1, 0], [0, 0, 1]], "Q2": [[1]]},
  "noise": {"process_covariance_per_period": [[20, 0, 0], [0, 20, 0], [0, 0, 20]], "measurement_covariance": [[2.5]]}})";

TEST(PlantDescription, DiscreteFormParses) {
  const PlantDescription p = parse_plant(kDiscrete, "discrete.json");
  EXPECT_EQ(p.form, PlantForm::kDiscrete);
  EXPECT_EQ(p.n(), 3U);
  EXPECT_EQ(p.a.rows, 0U);
  EXPECT_DOUBLE_EQ(p.phi(0, 0), 1.25);
  EXPECT_EQ(p.cost_form, CostForm::kDiscrete);
  EXPECT_FALSE(p.has_board);
  EXPECT_EQ(p.tracked_outputs, std::vector<std::size_t>{0});
}

// Continuous-only keys: an intensity is refused; a continuous cost or a table makes the
// parser read the plant as its exact continuous equivalent (zoh_inverse), refused naming the
// per-step covariance when no Q_c gives it, naming Phi when Φ has no real principal logarithm.
TEST(PlantDescription, DiscreteFormRefusesContinuousOnlyFieldsOrReadsItsContinuousEquivalent) {
  nlohmann::json j = nlohmann::json::parse(kDiscrete);
  nlohmann::json bad = j;
  bad["noise"]["process_intensity"] = bad["noise"]["process_covariance_per_period"];
  bad["noise"].erase("process_covariance_per_period");
  EXPECT_NE(error_of(bad.dump()).find("field 'noise.process_intensity': a continuous intensity needs a continuous plant"),
            std::string::npos);
  bad = j;
  bad["table"] = {{"granularity_us", 1000}, {"range_us", 10000}, {"max_bytes", 256}};
  bad["cost"] = {{"Q1c", j["cost"]["Q1"]}, {"Q2c", j["cost"]["Q2"]}};
  // 20·I per step is no white noise's sampling through this Φ (its Q_c is indefinite).
  EXPECT_NE(error_of(bad.dump()).find("field 'noise.process_covariance_per_period': the continuous intensity Q_c"),
            std::string::npos) << error_of(bad.dump());
  // A consistent one: Q_d of Q_c = I through the continuous equivalent (Van Loan).
  const PlantDescription disc = parse_plant(kDiscrete, "discrete.json");
  const DenseMatrix a = zoh_inverse(disc.phi, disc.gamma, 0.01).a;
  DenseMatrix vl = DenseMatrix::zeros(6, 6);
  set_block(vl, 0, 0, -a * 0.01);
  set_block(vl, 0, 3, identity(3) * 0.01);
  set_block(vl, 3, 3, transpose(a) * 0.01);
  const DenseMatrix e = expm(vl, "test");
  DenseMatrix qd = transpose(block(e, 3, 3, 3, 3)) * block(e, 0, 3, 3, 3);
  symmetrize(qd);
  bad["noise"]["process_covariance_per_period"] = {{qd(0, 0), qd(0, 1), qd(0, 2)}, {qd(1, 0), qd(1, 1), qd(1, 2)},
                                                   {qd(2, 0), qd(2, 1), qd(2, 2)}};
  const PlantDescription p = parse_plant(bad.dump(), "equivalent.json");
  EXPECT_LT(p.d2c_noise_relative_error, 1e-13);
  EXPECT_NEAR(p.process_intensity(1, 1), 1.0, 1e-12);
  EXPECT_TRUE(p.continuous());
  EXPECT_TRUE(p.from_discrete);
  EXPECT_TRUE(p.has_table);
  EXPECT_EQ(p.cost_form, CostForm::kContinuous);
  EXPECT_LT(p.d2c_relative_error, 1e-14);
  EXPECT_EQ(p.phi.rows, 0U);
  EXPECT_DOUBLE_EQ(p.d2c_phi(0, 0), 1.25);
  bad["Phi"][0][0] = -1.25;
  EXPECT_NE(error_of(bad.dump()).find("field 'Phi': eigenvalue -1.25 on the negative real axis"), std::string::npos)
      << error_of(bad.dump());
  bad = j;
  bad["A"] = j["Phi"];
  EXPECT_NE(error_of(bad.dump()).find("field 'A': belongs to the continuous form"), std::string::npos);
}

TEST(PlantDescription, SectionsFormErrorsNameTheField) {
  nlohmann::json j = nlohmann::json::parse(read_text(std::string(ONESHOT_PLANTS_DIR) + "/hdd_numre.json"));
  nlohmann::json bad = j;
  bad["sections"]["continuous"][0]["denominator"] = {2.0, 502.7, 1.011e6};
  EXPECT_NE(error_of(bad.dump()).find("field 'sections.continuous[0].denominator': must be monic"), std::string::npos);
  bad = j;
  bad["sections"]["discrete"][0]["notch"]["beta"] = 1.0;
  EXPECT_NE(error_of(bad.dump()).find("field 'sections.discrete[0].notch.beta'"), std::string::npos);
  bad = j;
  bad["sections"]["disturbance"]["reading"] = "printed";
  EXPECT_NE(error_of(bad.dump()).find("field 'sections.disturbance.reading'"), std::string::npos);
  bad = j;
  bad["C"] = {{1.0}};
  EXPECT_NE(error_of(bad.dump()).find("field 'C': is generated from 'sections'"), std::string::npos);
  bad = j;
  for (int i = 0; i < 7; ++i) bad["sections"]["continuous"].push_back(j["sections"]["continuous"][1]);
  EXPECT_NE(error_of(bad.dump()).find("exceed the supported maximum of 16 (kMaxStates"), std::string::npos);
}

TEST(PlantDescription, FileRoundTrip) {
  const std::string path = test::write_temp_file("reference.json", reference_plant_json());
  EXPECT_EQ(load_plant_file(path).a, reference_plant().a);
}

}  // namespace
}  // namespace oneshot::design
