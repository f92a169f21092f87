/// @file termination_cleanup.hpp
/// @brief What an interrupted run leaves behind: nothing. Child process groups are ended and
///        temporary files removed when the program receives SIGINT, SIGTERM or SIGHUP.
///
/// The handlers only use async-signal-safe calls (kill, unlink) on fixed tables filled by
/// the registration functions, then let the signal take its default action, so the exit
/// status still says which signal ended the program. A child is also started with
/// PR_SET_PDEATHSIG (child_process.hpp), which covers SIGKILL of the parent as well.
#pragma once

#include <string>

namespace oneshot::util {

/// Installs the handlers (once; a signal the caller ignores stays ignored).
void install_termination_handlers();

/// Adds a child process group to end with SIGKILL on termination; false when the table
/// (64 groups) is full.
bool register_child_group(int pgid);

/// Removes a group added by register_child_group (it has been waited for).
void unregister_child_group(int pgid);

/// A temporary file removed on termination, and on destruction unless committed().
class TempFileGuard {
 public:
  /// Registers `path` (longer than PATH_MAX: removed on destruction only).
  explicit TempFileGuard(const std::string& path);
  ~TempFileGuard();
  TempFileGuard(const TempFileGuard&) = delete;
  TempFileGuard& operator=(const TempFileGuard&) = delete;
  /// The file has been renamed into place: keep it.
  void committed() { committed_ = true; }

 private:
  std::string path_;
  int slot_ = -1;
  bool committed_ = false;
};

}  // namespace oneshot::util
