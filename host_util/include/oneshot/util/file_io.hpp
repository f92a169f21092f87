/// @file file_io.hpp
/// @brief Bounded reads of input files and atomic, checked writes of output files (host only).
///
/// Inputs (plant, scenario, trace files) are read up to a size limit, so `/dev/zero` or a
/// runaway file is refused instead of filling memory; a directory is named as one. Outputs
/// are written to a temporary file in the target's folder, synced, closed and renamed over
/// the target: a reader never sees half a file, and a failed write (full disk, I/O error,
/// file size limit) is an error that leaves the previous file, never a silent exit 0.
#pragma once

#include <cstddef>
#include <stdexcept>
#include <string>

namespace oneshot::util {

/// A file could not be read or written; what() names the path and the reason.
class FileError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Default limit of read_text_file: 16 MiB, far above any plant, scenario or trace file.
inline constexpr std::size_t kMaxInputFileBytes = std::size_t{16} << 20;

/// The whole content of `path`. FileError (naming `what`, e.g. "scenario file") when the
/// path is missing, a directory, unreadable, or longer than `max_bytes`.
std::string read_text_file(const std::string& path, const std::string& what,
                           std::size_t max_bytes = kMaxInputFileBytes);

/// read_text_file() whose FileError is rethrown as the caller's error type `Error` (the
/// study's input error), its message prefixed by `prefix` (e.g. "field 'links[0].file': ").
template <typename Error>
std::string read_text_file_as(const std::string& path, const std::string& what, const std::string& prefix = {},
                              std::size_t max_bytes = kMaxInputFileBytes) {
  try {
    return read_text_file(path, what, max_bytes);
  } catch (const FileError& e) {
    throw Error(prefix + e.what());
  }
}

/// Writes `bytes` to `path` atomically: temporary file in the same folder, every write,
/// fsync and close checked, then rename. Missing parent folders are created. An existing
/// non-regular target (a device such as /dev/null or /dev/stdout, a pipe) is written in
/// place, still checked. FileError naming the path and the system's reason on any failure;
/// the temporary file is removed then (and by the termination handlers on a signal).
void write_file_atomic(const std::string& path, const std::string& bytes);

/// Creates `dir` and its parents (FileError naming it when impossible or not a folder).
void create_directories(const std::string& dir);

}  // namespace oneshot::util
