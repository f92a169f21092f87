/// @file temp_files.hpp
/// @brief Scratch folders and whole-file reads for the CLI tests.
#pragma once

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <unistd.h>

namespace oneshot::test {

/// An empty path under the temporary folder, unique to this process: PREFIX_PID_NAME (removed first).
inline std::string fresh_dir(const std::string& prefix, const std::string& name) {
  const auto d = std::filesystem::temp_directory_path() / (prefix + "_" + std::to_string(::getpid()) + "_" + name);
  std::filesystem::remove_all(d);
  return d.string();
}

/// fresh_dir(prefix, name), created empty.
inline std::string made_dir(const std::string& prefix, const std::string& name) {
  const std::string d = fresh_dir(prefix, name);
  std::filesystem::create_directories(d);
  return d;
}

/// The whole file, bytes as stored ("" when it cannot be opened).
inline std::string read_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

}  // namespace oneshot::test
