/// @file child_process.cpp
/// @brief fork + execve with an argument vector (see child_process.hpp).
#include "oneshot/util/child_process.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cerrno>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <fcntl.h>
#include <sys/prctl.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <thread>
#include <unistd.h>

#include "oneshot/util/termination_cleanup.hpp"

extern char** environ;

namespace oneshot::util {
namespace {

/// What the child reports through the error pipe when it cannot exec.
struct ChildFailure {
  int stage;  // 0: chdir, 1: exec, 2: descriptors
  int error;
};

/// The child side, between fork and exec: async-signal-safe calls only.
[[noreturn]] void child_main(const char* program, char* const* argv, const ProcessSpec& spec, int null_fd,
                             int report_fd, pid_t parent) {
  ::setpgid(0, 0);
  ::prctl(PR_SET_PDEATHSIG, SIGKILL);
  if (::getppid() != parent) ::_exit(127);  // the parent is already gone
  for (int sig : {SIGINT, SIGTERM, SIGHUP}) {  // our handlers are not the child's; an ignored signal stays ignored
    struct sigaction cur {};
    if (::sigaction(sig, nullptr, &cur) == 0 && cur.sa_handler != SIG_IGN) ::signal(sig, SIG_DFL);
  }
  ::signal(SIGPIPE, SIG_DFL);  // oneshot-sim ignores it for itself only
  sigset_t none;
  sigemptyset(&none);
  ::sigprocmask(SIG_SETMASK, &none, nullptr);
  const auto fail = [&](int stage) {
    const ChildFailure f{stage, errno};
    [[maybe_unused]] const ssize_t w = ::write(report_fd, &f, sizeof f);
    ::_exit(127);
  };
  const auto place = [&](int from, int to) {
    if (from == to) {
      if (::fcntl(to, F_SETFD, 0) != 0) fail(2);  // keep it across exec
    } else if (::dup2(from, to) < 0) {
      fail(2);
    }
  };
  place(spec.stdin_fd >= 0 ? spec.stdin_fd : null_fd, STDIN_FILENO);
  if (spec.stdout_fd >= 0) place(spec.stdout_fd, STDOUT_FILENO);
  if (spec.stderr_fd >= 0) place(spec.stderr_fd, STDERR_FILENO);
  for (const auto& [from, to] : spec.extra_fds) place(from, to);
  if (!spec.working_dir.empty() && ::chdir(spec.working_dir.c_str()) != 0) fail(0);
  ::execve(program, argv, environ);
  fail(1);
  ::_exit(127);
}

}  // namespace

std::string ExitStatus::describe() const {
  if (exited) return "exit code " + std::to_string(code);
  const char* name = ::strsignal(signal);
  return "killed by signal " + std::to_string(signal) + (name != nullptr ? std::string(" (") + name + ")" : "");
}

std::string find_program(const std::string& program) {
  if (program.empty()) return {};
  const auto runnable = [](const std::string& p) {
    struct stat st {};
    return ::stat(p.c_str(), &st) == 0 && S_ISREG(st.st_mode) && ::access(p.c_str(), X_OK) == 0;
  };
  if (program.find('/') != std::string::npos) return runnable(program) ? program : std::string();
  const char* path = std::getenv("PATH");
  const std::string dirs = path != nullptr ? path : "/usr/local/bin:/usr/bin:/bin";
  std::size_t start = 0;
  while (start <= dirs.size()) {
    const std::size_t end = std::min(dirs.find(':', start), dirs.size());
    const std::string dir = end > start ? dirs.substr(start, end - start) : ".";
    const std::string candidate = dir + "/" + program;
    if (runnable(candidate)) return candidate;
    start = end + 1;
  }
  return {};
}

ChildProcess::ChildProcess(const ProcessSpec& spec) {
  if (spec.argv.empty()) throw ProcessError("no program to start");
  const std::string program = find_program(spec.argv[0]);
  if (program.empty()) throw ProcessError(spec.argv[0] + ": not found (not installed, or not on PATH)");
  std::vector<std::string> args = spec.argv;
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  const int null_fd = ::open("/dev/null", O_RDONLY | O_CLOEXEC);
  int report[2];
  if (null_fd < 0 || ::pipe2(report, O_CLOEXEC) != 0) {
    if (null_fd >= 0) ::close(null_fd);
    throw ProcessError(spec.argv[0] + ": cannot start: " + std::strerror(errno));
  }
  // Block the termination signals across fork: the child must not run our handlers.
  sigset_t all;
  sigset_t old;
  sigfillset(&all);
  ::pthread_sigmask(SIG_SETMASK, &all, &old);
  const pid_t parent = ::getpid();
  const pid_t pid = ::fork();
  if (pid == 0) child_main(program.c_str(), argv.data(), spec, null_fd, report[1], parent);
  const int fork_error = errno;
  if (pid > 0) {
    ::setpgid(pid, pid);  // also done by the child; whichever runs first
    register_child_group(pid);
  }
  ::pthread_sigmask(SIG_SETMASK, &old, nullptr);
  ::close(null_fd);
  ::close(report[1]);
  if (pid < 0) {
    ::close(report[0]);
    throw ProcessError(spec.argv[0] + ": cannot start: " + std::strerror(fork_error));
  }
  pid_ = pid;
  ChildFailure failure{};
  ssize_t n = 0;
  do {
    n = ::read(report[0], &failure, sizeof failure);
  } while (n < 0 && errno == EINTR);
  ::close(report[0]);
  if (n == static_cast<ssize_t>(sizeof failure)) {
    wait();
    const char* what = failure.stage == 0 ? "cannot enter the folder '" : "cannot run '";
    const std::string object = failure.stage == 0 ? spec.working_dir : program;
    throw ProcessError(spec.argv[0] + ": " + what + object + "': " + std::strerror(failure.error));
  }
}

ChildProcess::~ChildProcess() {
  if (!done_ && pid_ > 0) terminate();
}

ExitStatus ChildProcess::reap(int status) {
  done_ = true;
  unregister_child_group(pid_);
  status_.exited = WIFEXITED(status);
  status_.code = status_.exited ? WEXITSTATUS(status) : -1;
  status_.signal = WIFSIGNALED(status) ? WTERMSIG(status) : 0;
  return status_;
}

ExitStatus ChildProcess::wait() {
  if (done_) return status_;
  int status = 0;
  while (::waitpid(pid_, &status, 0) < 0) {
    if (errno != EINTR) {
      done_ = true;
      unregister_child_group(pid_);
      return status_;
    }
  }
  return reap(status);
}

bool ChildProcess::wait_for(int timeout_ms) {
  if (done_) return true;
  for (int waited = 0;; waited += 5) {
    int status = 0;
    const pid_t r = ::waitpid(pid_, &status, WNOHANG);
    if (r == pid_) {
      reap(status);
      return true;
    }
    if (r < 0 && errno != EINTR) {
      done_ = true;
      unregister_child_group(pid_);
      return true;
    }
    if (waited >= timeout_ms) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
}

ExitStatus ChildProcess::terminate(int grace_ms) {
  if (done_) return status_;
  ::kill(-pid_, SIGTERM);
  for (int waited = 0; waited < grace_ms; waited += 5) {
    int status = 0;
    const pid_t r = ::waitpid(pid_, &status, WNOHANG);
    if (r == pid_) {
      ::kill(-pid_, SIGKILL);  // anything it left in its group
      return reap(status);
    }
    if (r < 0 && errno != EINTR) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  ::kill(-pid_, SIGKILL);
  return wait();
}

CapturedRun run_captured(ProcessSpec spec, std::size_t max_output) {
  int out[2];
  if (::pipe2(out, O_CLOEXEC) != 0) throw ProcessError("cannot create a pipe: " + std::string(std::strerror(errno)));
  spec.stdout_fd = out[1];
  spec.stderr_fd = out[1];
  CapturedRun r;
  try {
    ChildProcess child(spec);
    ::close(out[1]);
    out[1] = -1;
    std::array<char, 4096> buf{};
    for (;;) {
      const ssize_t n = ::read(out[0], buf.data(), buf.size());
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) break;
      const std::size_t keep = std::min(static_cast<std::size_t>(n), max_output - std::min(max_output, r.output.size()));
      r.output.append(buf.data(), keep);
    }
    ::close(out[0]);
    out[0] = -1;
    r.status = child.wait();
  } catch (...) {
    if (out[0] >= 0) ::close(out[0]);
    if (out[1] >= 0) ::close(out[1]);
    throw;
  }
  return r;
}

}  // namespace oneshot::util
