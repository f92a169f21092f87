/// @file output_files.hpp
/// @brief CSV and JSON files of the experiments, and plots drawn by gnuplot.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace oneshot::sim {

/// Writes a CSV: header line, then rows of numbers with 9 significant digits.
void write_csv(const std::string& path, const std::vector<std::string>& header,
               const std::vector<std::vector<double>>& rows);

/// Writes `j` pretty-printed to `path`, or to standard output when path is "-".
void write_json(const std::string& path, const nlohmann::json& j);

/// Creates `dir` (and parents); std::runtime_error naming it when impossible.
void make_directory(const std::string& dir);

/// Runs `script` with gnuplot in `dir`; std::runtime_error with gnuplot's message on
/// failure, or when gnuplot is not installed (apt-get install gnuplot-nox).
void run_gnuplot(const std::string& dir, const std::string& script_name, const std::string& script);

}  // namespace oneshot::sim
