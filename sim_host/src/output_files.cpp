/// @file output_files.cpp
/// @brief Output files and plots.
#include "oneshot/sim/output_files.hpp"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <stdexcept>

#include "oneshot/host/child_process.hpp"
#include "oneshot/host/file_io.hpp"
#include "oneshot/host/strict_json.hpp"

namespace oneshot::sim {

void write_csv(const std::string& path, const std::vector<std::string>& header,
               const std::vector<std::vector<double>>& rows, NonFinite non_finite) {
  std::string out;
  for (std::size_t i = 0; i < header.size(); ++i) out += (i ? "," : "") + header[i];
  out += "\n";
  char buf[32];
  for (std::size_t r = 0; r < rows.size(); ++r) {
    for (std::size_t i = 0; i < rows[r].size(); ++i) {
      if (!std::isfinite(rows[r][i])) {
        if (non_finite == NonFinite::kMissing) {
          out += (i ? ",nan" : "nan");
          continue;
        }
        throw std::runtime_error(path + ": row " + std::to_string(r + 1) + ", column '" +
                                 (i < header.size() ? header[i] : std::to_string(i + 1)) +
                                 "' is not a finite number: the run diverged or its inputs are out of range");
      }
      std::snprintf(buf, sizeof buf, "%.9g", rows[r][i]);
      out += (i ? "," : "");
      out += buf;
    }
    out += "\n";
  }
  write_text(path, out);
}

void write_json(const std::string& path, const nlohmann::json& j) {
  std::string text;
  try {
    text = host::dump_finite(j) + "\n";
  } catch (const host::JsonError& e) {
    throw std::runtime_error((path == "-" ? std::string("JSON result") : path) + ": " + e.what());
  }
  if (path == "-") {
    std::cout << text << std::flush;
    if (!std::cout) throw std::runtime_error("standard output: write failed");
    return;
  }
  write_text(path, text);
}

void write_text(const std::string& path, const std::string& text) { host::write_file_atomic(path, text); }

void make_directory(const std::string& dir) { host::create_directories(dir); }

std::string gnuplot_quote(const std::string& label) {
  std::string q = "'";
  for (const char c : label) {
    const auto u = static_cast<unsigned char>(c);
    if (c == '\'') {
      q += "''";
    } else if (u < 0x20 || u == 0x7F) {
      q += ' ';
    } else {
      q += c;
    }
  }
  return q + "'";
}

void run_gnuplot(const std::string& dir, const std::string& script_name, const std::string& script) {
  write_text((std::filesystem::path(dir) / script_name).string(), script);
  host::ProcessSpec spec;
  spec.argv = {"gnuplot", script_name};
  spec.working_dir = dir;
  host::CapturedRun r;
  try {
    r = host::run_captured(spec);
  } catch (const host::ProcessError& e) {
    throw std::runtime_error(std::string("cannot run gnuplot (apt-get install gnuplot-nox), or use --no-plots: ") +
                             e.what());
  }
  if (!r.status.success()) {
    throw std::runtime_error("gnuplot failed on " + (std::filesystem::path(dir) / script_name).string() + " (" +
                             r.status.describe() + "):\n" + r.output);
  }
}

}  // namespace oneshot::sim
