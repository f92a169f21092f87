/// @file run_command.hpp
/// @brief Runs a program from an argument vector (no shell) and captures its exit status
///        and combined output.
#pragma once

#include <functional>
#include <string>
#include <vector>

namespace oneshot::test {

/// Exit status and standard output + error of a finished command.
struct CommandResult {
  int exit_code = -1;    ///< Exit code, or −1 when killed by a signal.
  int signal = 0;        ///< Signal that ended it (0: exited).
  std::string output;    ///< Standard output and error, interleaved.
};

/// Extra settings of a run.
struct CommandOptions {
  long file_size_limit_bytes = -1;  ///< RLIMIT_FSIZE for the child (SIGXFSZ ignored): writes beyond fail.
  std::vector<std::string> env;     ///< Extra NAME=VALUE entries of its environment.
  std::string working_dir;          ///< Folder to run in (empty: ours).
  std::string stdout_path;          ///< Its standard output goes to this file (only standard error is captured).
};

/// Runs argv[0] (a path, or a name looked up on PATH) with `argv`; every argument reaches
/// the program unchanged, whatever characters it holds.
CommandResult run_command(const std::vector<std::string>& argv, const CommandOptions& options = {});

/// The older form: `command` is split at spaces into an argument vector (no shell, no
/// quoting, no redirection; for arguments without spaces).
CommandResult run_command(const std::string& command);

/// A program running in the background, its output collected in a file (for tests that
/// signal it or watch what it does while it runs).
class BackgroundCommand {
 public:
  /// Starts `argv` like run_command.
  explicit BackgroundCommand(const std::vector<std::string>& argv, const CommandOptions& options = {});
  /// Kills (SIGKILL) and reaps it if it is still running.
  ~BackgroundCommand();
  BackgroundCommand(const BackgroundCommand&) = delete;
  BackgroundCommand& operator=(const BackgroundCommand&) = delete;
  /// Its process id.
  int pid() const { return pid_; }
  /// Waits up to `timeout_ms` for it to end (then SIGKILL); its status and output.
  CommandResult wait(int timeout_ms);

 private:
  int pid_ = -1;
  bool reaped_ = false;
  std::string output_path_;
};

/// Process ids of the processes whose environment holds exactly `entry` (NAME=VALUE).
std::vector<int> processes_with_environment(const std::string& entry);

/// Polls `condition` every 20 ms for up to `timeout_ms`; whether it became true.
bool eventually(const std::function<bool()>& condition, int timeout_ms);

/// Writes `text` to a fresh file under the test temp dir and returns its path.
std::string write_temp_file(const std::string& name, const std::string& text);

}  // namespace oneshot::test
