/// @file temp_files.hpp
/// @brief Scratch folders (removed when the test process ends) and whole-file reads for the
///        CLI tests.
#pragma once

#include <filesystem>
#include <fstream>
#include <mutex>
#include <sstream>
#include <string>
#include <system_error>
#include <utility>
#include <vector>
#include <unistd.h>

namespace oneshot::test {

/// A folder removed with everything in it when this object ends (RAII; movable, not copyable).
class TempDir {
 public:
  /// Owns `path` (nothing is created here).
  explicit TempDir(std::string path) : path_(std::move(path)) {}
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  /// Takes over the folder of `other` (which then owns none).
  TempDir(TempDir&& other) noexcept : path_(std::exchange(other.path_, std::string())) {}
  TempDir& operator=(TempDir&&) = delete;
  ~TempDir() {
    if (path_.empty()) return;
    std::error_code ec;  // never throws: a folder already gone is fine
    std::filesystem::remove_all(path_, ec);
  }
  const std::string& path() const { return path_; }  ///< The folder.

 private:
  std::string path_;
};

/// Keeps `path` until the test process ends, then removes it with everything in it (the
/// folders of fresh_dir(), made_dir() and write_temp_file()); returns `path`.
inline std::string remove_at_exit(std::string path) {
  static std::mutex lock;
  static std::vector<TempDir> dirs;  // destroyed, so removed, when the process exits normally
  const std::lock_guard<std::mutex> hold(lock);
  dirs.emplace_back(path);
  return path;
}

/// An empty path under the temporary folder, unique to this process: PREFIX_PID_NAME (removed
/// first, and again when the process ends).
inline std::string fresh_dir(const std::string& prefix, const std::string& name) {
  const auto d = std::filesystem::temp_directory_path() / (prefix + "_" + std::to_string(::getpid()) + "_" + name);
  std::filesystem::remove_all(d);
  return remove_at_exit(d.string());
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
