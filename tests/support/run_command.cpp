/// @file run_command.cpp
/// @brief fork + exec with an argument vector for the CLI tests (see run_command.hpp).
#include "support/run_command.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <thread>
#include <cerrno>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <fcntl.h>
#include <sstream>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

extern char** environ;

namespace oneshot::test {

namespace {

/// fork + exec of `argv` with standard output and error on `out_fd`; the child's pid or −1.
pid_t spawn(const std::vector<std::string>& argv, const CommandOptions& options, int out_fd) {
  if (argv.empty()) return -1;
  std::vector<std::string> args = argv;
  std::vector<char*> cargs;
  for (std::string& a : args) cargs.push_back(a.data());
  cargs.push_back(nullptr);
  std::vector<std::string> env_strings;
  for (char** e = environ; *e != nullptr; ++e) env_strings.emplace_back(*e);
  env_strings.insert(env_strings.end(), options.env.begin(), options.env.end());
  std::vector<char*> cenv;
  for (std::string& e : env_strings) cenv.push_back(e.data());
  cenv.push_back(nullptr);
  const pid_t pid = ::fork();  // only async-signal-safe calls in the child until exec
  if (pid == 0) {
    // As from an interactive terminal, whatever ran the tests (a background shell ignores SIGINT).
    for (int sig : {SIGINT, SIGTERM, SIGHUP, SIGPIPE}) ::signal(sig, SIG_DFL);
    ::dup2(out_fd, STDOUT_FILENO);
    ::dup2(out_fd, STDERR_FILENO);
    if (!options.stdout_path.empty()) {
      const int fd = ::open(options.stdout_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      if (fd < 0 || ::dup2(fd, STDOUT_FILENO) < 0) ::_exit(126);
    }
    const int null_fd = ::open("/dev/null", O_RDONLY);
    if (null_fd >= 0) ::dup2(null_fd, STDIN_FILENO);
    if (options.file_size_limit_bytes >= 0) {
      ::signal(SIGXFSZ, SIG_IGN);  // a write past the limit fails with EFBIG instead
      const auto limit = static_cast<rlim_t>(options.file_size_limit_bytes);
      const rlimit lim{limit, limit};
      ::setrlimit(RLIMIT_FSIZE, &lim);
    }
    if (!options.working_dir.empty() && ::chdir(options.working_dir.c_str()) != 0) ::_exit(126);
    ::execvpe(cargs[0], cargs.data(), cenv.data());
    const char* msg = "run_command: cannot execute the program\n";
    [[maybe_unused]] const ssize_t w = ::write(STDERR_FILENO, msg, std::strlen(msg));
    ::_exit(127);
  }
  return pid;
}

void decode_status(int status, CommandResult& r) {
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.signal = WIFSIGNALED(status) ? WTERMSIG(status) : 0;
}

}  // namespace

CommandResult run_command(const std::vector<std::string>& argv, const CommandOptions& options) {
  CommandResult r;
  int out[2];
  if (::pipe2(out, O_CLOEXEC) != 0) return r;
  const pid_t pid = spawn(argv, options, out[1]);
  ::close(out[1]);
  if (pid < 0) {
    ::close(out[0]);
    return r;
  }
  std::array<char, 4096> buf{};
  for (;;) {
    const ssize_t n = ::read(out[0], buf.data(), buf.size());
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;
    r.output.append(buf.data(), static_cast<std::size_t>(n));
  }
  ::close(out[0]);
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  decode_status(status, r);
  return r;
}

BackgroundCommand::BackgroundCommand(const std::vector<std::string>& argv, const CommandOptions& options) {
  static int counter = 0;
  output_path_ = write_temp_file("background_" + std::to_string(counter++) + ".out", "");
  const int fd = ::open(output_path_.c_str(), O_WRONLY | O_TRUNC | O_CLOEXEC);
  pid_ = fd >= 0 ? spawn(argv, options, fd) : -1;
  if (fd >= 0) ::close(fd);
}

BackgroundCommand::~BackgroundCommand() {
  if (pid_ > 0 && !reaped_) {
    ::kill(pid_, SIGKILL);
    int status = 0;
    ::waitpid(pid_, &status, 0);
  }
}

CommandResult BackgroundCommand::wait(int timeout_ms) {
  CommandResult r;
  if (pid_ <= 0 || reaped_) return r;
  int status = 0;
  const bool ended = eventually([&] { return ::waitpid(pid_, &status, WNOHANG) == pid_; }, timeout_ms);
  if (!ended) {
    ::kill(pid_, SIGKILL);
    ::waitpid(pid_, &status, 0);
  }
  reaped_ = true;
  decode_status(status, r);
  std::ifstream in(output_path_, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  r.output = s.str();
  return r;
}

std::vector<int> processes_with_environment(const std::string& entry) {
  std::vector<int> found;
  for (const auto& e : std::filesystem::directory_iterator("/proc")) {
    const std::string name = e.path().filename().string();
    if (name.empty() || !std::all_of(name.begin(), name.end(), [](char c) { return c >= '0' && c <= '9'; })) continue;
    std::ifstream env(e.path() / "environ", std::ios::binary);
    std::string var;
    while (std::getline(env, var, '\0')) {
      if (var == entry) {
        found.push_back(std::stoi(name));
        break;
      }
    }
  }
  return found;
}

bool eventually(const std::function<bool()>& condition, int timeout_ms) {
  for (int waited = 0;; waited += 20) {
    if (condition()) return true;
    if (waited >= timeout_ms) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
}

CommandResult run_command(const std::string& command) {
  std::vector<std::string> argv;
  std::istringstream words(command);
  std::string w;
  while (words >> w) argv.push_back(w);
  return run_command(argv);
}

}  // namespace oneshot::test
