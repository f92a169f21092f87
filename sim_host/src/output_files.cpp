/// @file output_files.cpp
/// @brief Output files and plots.
#include "oneshot/sim/output_files.hpp"

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <stdexcept>
#include <sys/wait.h>

namespace oneshot::sim {

void write_csv(const std::string& path, const std::vector<std::string>& header,
               const std::vector<std::vector<double>>& rows) {
  std::ofstream out(path, std::ios::binary);
  if (!out) throw std::runtime_error(path + ": cannot write");
  for (std::size_t i = 0; i < header.size(); ++i) out << (i ? "," : "") << header[i];
  out << "\n";
  char buf[32];
  for (const auto& row : rows) {
    for (std::size_t i = 0; i < row.size(); ++i) {
      std::snprintf(buf, sizeof buf, "%.9g", row[i]);
      out << (i ? "," : "") << buf;
    }
    out << "\n";
  }
  if (!out) throw std::runtime_error(path + ": write failed");
}

void write_json(const std::string& path, const nlohmann::json& j) {
  if (path == "-") {
    std::cout << j.dump(2) << "\n";
    return;
  }
  std::ofstream out(path, std::ios::binary);
  out << j.dump(2) << "\n";
  if (!out) throw std::runtime_error(path + ": cannot write");
}

void make_directory(const std::string& dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec || !std::filesystem::is_directory(dir)) throw std::runtime_error(dir + ": cannot create the output directory");
}

void run_gnuplot(const std::string& dir, const std::string& script_name, const std::string& script) {
  const std::string path = (std::filesystem::path(dir) / script_name).string();
  {
    std::ofstream out(path, std::ios::binary);
    out << script;
    if (!out) throw std::runtime_error(path + ": cannot write");
  }
  const std::string command = "cd '" + dir + "' && gnuplot '" + script_name + "' 2>&1";
  FILE* pipe = ::popen(command.c_str(), "r");
  if (pipe == nullptr) throw std::runtime_error("cannot start gnuplot");
  std::string output;
  std::array<char, 512> buf{};
  std::size_t n = 0;
  while ((n = std::fread(buf.data(), 1, buf.size(), pipe)) > 0) output.append(buf.data(), n);
  const int status = ::pclose(pipe);
  if (!WIFEXITED(status) || WEXITSTATUS(status) == 127) {
    throw std::runtime_error("gnuplot is not installed (apt-get install gnuplot-nox), or use --no-plots");
  }
  if (WEXITSTATUS(status) != 0) throw std::runtime_error("gnuplot failed on " + path + ":\n" + output);
}

}  // namespace oneshot::sim
