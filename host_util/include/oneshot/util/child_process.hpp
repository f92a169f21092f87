/// @file child_process.hpp
/// @brief Starting other programs without a shell: an argument vector, its own process
///        group, ended with the parent.
///
/// No command line is ever built or parsed: every argument reaches the program as it is,
/// so quotes, `$(…)`, `;` or newlines in a file name or label are data. The child runs in
/// a new process group (a terminal's Ctrl-C reaches only us, and we end the whole group),
/// with PR_SET_PDEATHSIG = SIGKILL (it dies when the thread that started it ends, even if
/// the parent is killed with SIGKILL), and its group is registered with the termination
/// handlers (termination_cleanup.hpp).
#pragma once

#include <cstddef>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace oneshot::util {

/// A program could not be started (not installed, not executable, bad folder).
class ProcessError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// How a child ended.
struct ExitStatus {
  bool exited = false;  ///< Exited normally (code is valid); otherwise killed by `signal`.
  int code = -1;        ///< Exit code.
  int signal = 0;       ///< Signal that ended it.
  /// Exited with code 0.
  bool success() const { return exited && code == 0; }
  /// "exit code N" or "killed by signal S (name)".
  std::string describe() const;
};

/// What to start.
struct ProcessSpec {
  std::vector<std::string> argv;  ///< Program and arguments; argv[0] is looked up on PATH unless it has a '/'.
  std::string working_dir;        ///< Folder to run in (empty: ours).
  int stdin_fd = -1;              ///< Descriptor for its standard input (-1: /dev/null).
  int stdout_fd = -1;             ///< For its standard output (-1: ours).
  int stderr_fd = -1;             ///< For its standard error (-1: ours).
  std::vector<std::pair<int, int>> extra_fds;  ///< (our descriptor, its number ≥ 3) passed on.
};

/// A started child process and its process group.
class ChildProcess {
 public:
  /// Starts `spec`; ProcessError naming the program and the reason when it cannot run.
  explicit ChildProcess(const ProcessSpec& spec);
  /// Ends the group (terminate()) unless it has been waited for.
  ~ChildProcess();
  ChildProcess(const ChildProcess&) = delete;
  ChildProcess& operator=(const ChildProcess&) = delete;

  /// Process id (= its process group id).
  int pid() const { return pid_; }
  /// Waits for the child to end.
  ExitStatus wait();
  /// Waits at most `timeout_ms` for the child to end; true when it has (then wait() returns
  /// its status at once).
  bool wait_for(int timeout_ms);
  /// SIGTERM to the group, SIGKILL after `grace_ms` if the child has not ended; waits.
  ExitStatus terminate(int grace_ms = 2000);

 private:
  ExitStatus reap(int status);
  int pid_ = -1;
  bool done_ = false;
  ExitStatus status_;
};

/// Output and status of a finished child.
struct CapturedRun {
  ExitStatus status;   ///< How it ended.
  std::string output;  ///< Standard output and error interleaved (at most max_output bytes).
};

/// Runs `spec` to the end with its standard output and error captured (their descriptors
/// in `spec` are ignored; standard input is /dev/null unless given).
CapturedRun run_captured(ProcessSpec spec, std::size_t max_output = std::size_t{1} << 20);

/// Full path of `program` on PATH, or empty when it is not there.
std::string find_program(const std::string& program);

}  // namespace oneshot::util
