/// @file file_io.cpp
/// @brief Bounded reads and atomic writes (see file_io.hpp).
#include "oneshot/util/file_io.hpp"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fcntl.h>
#include <filesystem>
#include <fstream>
#include <sys/stat.h>
#include <unistd.h>

#include "oneshot/util/termination_cleanup.hpp"

namespace oneshot::util {
namespace {

namespace fs = std::filesystem;

std::string reason(int err) { return std::strerror(err); }

/// Closes a descriptor on scope exit unless released.
struct Fd {
  int fd = -1;
  ~Fd() {
    if (fd >= 0) ::close(fd);
  }
  int release() {
    const int f = fd;
    fd = -1;
    return f;
  }
};

/// Writes all of `bytes` to `fd` (partial writes and EINTR handled); errno on failure.
int write_all(int fd, const std::string& bytes) {
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t w = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (w < 0 && errno == EINTR) continue;
    if (w < 0) return errno;
    if (w == 0) return EIO;
    done += static_cast<std::size_t>(w);
  }
  return 0;
}

/// The process umask, read without changing it (Linux ≥ 4.7 reports it in /proc).
mode_t current_umask() {
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line)) {
    if (line.rfind("Umask:", 0) == 0) return static_cast<mode_t>(std::stoul(line.substr(6), nullptr, 8));
  }
  return 022;
}

/// Writes to an existing non-regular file (device, pipe) in place, checked.
void write_in_place(const std::string& path, const std::string& bytes) {
  Fd f{::open(path.c_str(), O_WRONLY | O_CLOEXEC | O_NOCTTY)};
  if (f.fd < 0) throw FileError(path + ": cannot write: " + reason(errno));
  if (const int err = write_all(f.fd, bytes)) throw FileError(path + ": write failed: " + reason(err));
  if (::close(f.release()) != 0) throw FileError(path + ": write failed: " + reason(errno));
}

}  // namespace

std::string read_text_file(const std::string& path, const std::string& what, std::size_t max_bytes) {
  Fd f{::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NOCTTY)};
  if (f.fd < 0) throw FileError(path + ": cannot read the " + what + ": " + reason(errno));
  struct stat st {};
  if (::fstat(f.fd, &st) != 0) throw FileError(path + ": cannot read the " + what + ": " + reason(errno));
  if (S_ISDIR(st.st_mode)) throw FileError(path + ": is a directory, not a " + what);
  std::string text;
  char buf[65536];
  for (;;) {
    const ssize_t n = ::read(f.fd, buf, sizeof buf);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) throw FileError(path + ": cannot read the " + what + ": " + reason(errno));
    if (n == 0) break;
    if (text.size() + static_cast<std::size_t>(n) > max_bytes) {
      throw FileError(path + ": longer than " + std::to_string(max_bytes) + " bytes, the limit for a " + what +
                      " (is it the right file?)");
    }
    text.append(buf, static_cast<std::size_t>(n));
  }
  return text;
}

void create_directories(const std::string& dir) {
  if (dir.empty()) return;
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (!fs::is_directory(dir)) {
    throw FileError(dir + ": cannot create the output folder" + (ec ? ": " + ec.message() : std::string()));
  }
}

void write_file_atomic(const std::string& path, const std::string& bytes) {
  if (path.empty()) throw FileError("empty output file name");
  struct stat st {};
  if (::stat(path.c_str(), &st) == 0 && !S_ISREG(st.st_mode)) {
    if (S_ISDIR(st.st_mode)) throw FileError(path + ": is a directory, not a file to write");
    write_in_place(path, bytes);
    return;
  }
  // Replace the file a symbolic link points to, not the link.
  std::error_code ec;
  fs::path target = fs::path(path);
  if (fs::is_symlink(target, ec)) target = fs::weakly_canonical(target, ec);
  const fs::path dir = target.has_parent_path() ? target.parent_path() : fs::path(".");
  create_directories(dir.string());
  std::string temp = (dir / ("." + target.filename().string() + ".tmp-XXXXXX")).string();
  Fd f{::mkostemp(temp.data(), O_CLOEXEC)};
  if (f.fd < 0) throw FileError(path + ": cannot create a file in " + dir.string() + ": " + reason(errno));
  TempFileGuard guard(temp);
  const auto fail = [&](const char* what, int err) { throw FileError(path + ": " + what + ": " + reason(err)); };
  const mode_t mode = S_ISREG(st.st_mode) ? (st.st_mode & 07777) : (0666 & ~current_umask());
  if (::fchmod(f.fd, mode) != 0) fail("cannot set permissions", errno);
  if (const int err = write_all(f.fd, bytes)) fail("write failed", err);
  if (::fsync(f.fd) != 0) fail("write failed (sync)", errno);
  if (::close(f.release()) != 0) fail("write failed (close)", errno);
  if (::rename(temp.c_str(), target.c_str()) != 0) fail("cannot replace the file", errno);
  guard.committed();
  // Make the rename itself durable; a folder that cannot be synced is not an error.
  Fd d{::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC)};
  if (d.fd >= 0) ::fsync(d.fd);
}

}  // namespace oneshot::util
