/// @file output_files.cpp
/// @brief Output files and plots.
#include "oneshot/util/output_files.hpp"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <stdexcept>

#include "oneshot/util/child_process.hpp"
#include "oneshot/util/file_io.hpp"
#include "oneshot/util/strict_json.hpp"

namespace oneshot::util {

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
    text = util::dump_finite(j) + "\n";
  } catch (const util::JsonError& e) {
    throw std::runtime_error((path == "-" ? std::string("JSON result") : path) + ": " + e.what());
  }
  if (path == "-") {
    std::cout << text << std::flush;
    if (!std::cout) throw std::runtime_error("standard output: write failed");
    return;
  }
  write_text(path, text);
}

void write_text(const std::string& path, const std::string& text) { util::write_file_atomic(path, text); }

std::string path_in(const std::string& dir, const std::string& name) { return (std::filesystem::path(dir) / name).string(); }

void make_directory(const std::string& dir) { util::create_directories(dir); }

std::string gnuplot_png_terminal(int width_px, int height_px, int font_pt) {
  return "set terminal pngcairo size " + std::to_string(width_px) + "," + std::to_string(height_px) + " font 'Sans," +
         std::to_string(font_pt) + "' noenhanced\n";
}

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
  write_text(path_in(dir, script_name), script);
  util::ProcessSpec spec;
  spec.argv = {"gnuplot", script_name};
  spec.working_dir = dir;
  util::CapturedRun r;
  try {
    r = util::run_captured(spec);
  } catch (const util::ProcessError& e) {
    throw std::runtime_error(std::string("cannot run gnuplot (apt-get install gnuplot-nox), or use --no-plots: ") +
                             e.what());
  }
  if (!r.status.success()) {
    throw std::runtime_error("gnuplot failed on " + path_in(dir, script_name) + " (" +
                             r.status.describe() + "):\n" + r.output);
  }
}

}  // namespace oneshot::util
