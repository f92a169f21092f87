/// @file test_plants.cpp
/// @brief Test plants.
#include "support/test_plants.hpp"

#include <nlohmann/json.hpp>
#include <unistd.h>

#include <vector>

namespace oneshot::test {

namespace {

/// The n × n matrix s I as a JSON array of rows.
nlohmann::json scaled_identity(std::size_t n, double s) {
  nlohmann::json rows = nlohmann::json::array();
  for (std::size_t i = 0; i < n; ++i) {
    nlohmann::json row = nlohmann::json::array();
    for (std::size_t k = 0; k < n; ++k) row.push_back(i == k ? s : 0.0);
    rows.push_back(row);
  }
  return rows;
}

/// The vector [v, ..., v] of n entries as a JSON array.
nlohmann::json filled(std::size_t n, double v) { return nlohmann::json(std::vector<double>(n, v)); }

}  // namespace

std::string plant_json(const std::string& a, const std::string& b, const std::string& c, const std::string& extra) {
  nlohmann::json j = nlohmann::json::parse(design::reference_plant_json());
  j["A"] = nlohmann::json::parse(a);
  j["B"] = nlohmann::json::parse(b);
  j["C"] = nlohmann::json::parse(c);
  const std::size_t n = j["A"].size();
  const std::size_t m = j["B"][0].size();
  const std::size_t p = j["C"].size();
  j.erase("states");
  j.erase("inputs");
  j.erase("outputs");
  j["cost"]["Q1c"] = scaled_identity(n, 1.0);
  j["noise"]["process_covariance_per_period"] = scaled_identity(n, 2e-7);
  // Per output: R = 8e-5 I and the ADC range ±1.65 V; per input: Q2c = I and the PWM levels ±1.65 V.
  j["noise"]["measurement_covariance"] = scaled_identity(p, 8e-5);
  j["board"]["adc_min_volts"] = filled(p, -1.65);
  j["board"]["adc_max_volts"] = filled(p, 1.65);
  j["cost"]["Q2c"] = scaled_identity(m, 1.0);
  j["board"]["pwm_low_volts"] = filled(m, -1.65);
  j["board"]["pwm_high_volts"] = filled(m, 1.65);
  j["table"]["max_bytes"] = 2048;  // room for 3-state and double tables
  j.merge_patch(nlohmann::json::parse(extra));
  return j.dump();
}

design::PlantDescription damped_oscillator() {
  // ẍ = −ω² x − 2ζω ẋ + ω² u, ω = 30, ζ = 0.2.
  return design::parse_plant(plant_json("[[0, 1], [-900, -12]]", "[[0], [900]]", "[[1, 0]]",
                                        R"({"name": "damped-oscillator"})"),
                             "damped oscillator");
}

design::PlantDescription unstable_plant() {
  return design::parse_plant(plant_json("[[8, 1], [0, -15]]", "[[0], [15]]", "[[1, 0]]", R"({"name": "unstable"})"),
                             "unstable plant");
}

design::PlantDescription three_state_plant() {
  return design::parse_plant(plant_json("[[-2, 5, 0], [0, -1, 10], [1, 0, -20]]", "[[0], [0], [20]]",
                                        "[[1, 0, 0]]", R"({"name": "three-state"})"),
                             "three-state plant");
}

std::string reference_with(const std::string& pointer, const std::string& value_json) {
  nlohmann::json j = nlohmann::json::parse(design::reference_plant_json());
  const nlohmann::json::json_pointer ptr(pointer);
  if (value_json.empty()) {
    j[ptr.parent_pointer()].erase(ptr.back());
  } else {
    j[ptr] = nlohmann::json::parse(value_json);
  }
  return j.dump();
}

}  // namespace oneshot::test

#include <filesystem>
#include <fstream>

#include "support/run_command.hpp"
#include "support/temp_files.hpp"

namespace oneshot::test {

std::string write_temp_file(const std::string& name, const std::string& text) {
  static const std::string dir_name =  // removed when the process ends
      remove_at_exit((std::filesystem::temp_directory_path() / ("oneshot_test_" + std::to_string(::getpid()))).string());
  const std::filesystem::path dir = dir_name;
  std::filesystem::create_directories(dir);
  const auto path = dir / name;
  std::ofstream(path, std::ios::binary) << text;
  return path.string();
}

}  // namespace oneshot::test
