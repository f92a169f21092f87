/// @file pil_link.cpp
/// @brief QEMU process, framing and retries (see pil_link.hpp).
#include "oneshot/sim/pil_link.hpp"

#include <cerrno>
#include <fcntl.h>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <poll.h>
#include <sstream>
#include <sys/mman.h>
#include <unistd.h>

#include "oneshot/util/child_process.hpp"
#include "oneshot/util/file_io.hpp"

namespace oneshot::sim {

namespace fs = std::filesystem;
namespace pil = app::pil;

std::string firmware_image_path(const PilOptions& o) {
  const std::string dir = o.firmware_dir.empty() ? std::string(ONESHOT_DEFAULT_FIRMWARE_DIR) : o.firmware_dir;
  const std::string name =
      o.image_name.empty() ? "oneshot-" + o.target + "-" + o.format + "-" + o.discretizer + ".elf" : o.image_name;
  return (fs::path(dir) / ("firmware-" + o.target) / name).string();
}

std::uint32_t elf_symbol_address(const std::string& path, const std::string& name) {
  const std::string data = util::read_text_file_as<PilError>(path, "firmware image", {}, kMaxImageBytes);
  const auto u16 = [&](std::size_t off) {
    if (off + 2 > data.size()) throw PilError(path + ": truncated ELF");
    return static_cast<std::uint32_t>(static_cast<unsigned char>(data[off]) | static_cast<unsigned char>(data[off + 1]) << 8);
  };
  const auto u32 = [&](std::size_t off) { return u16(off) | u16(off + 2) << 16; };
  if (data.size() < 52 || data.compare(0, 4, "\x7f" "ELF") != 0 || data[4] != 1 || data[5] != 1) {
    throw PilError(path + ": not a 32-bit little-endian ELF file");
  }
  const std::uint32_t shoff = u32(32);
  const std::uint32_t shentsize = u16(46);
  const std::uint32_t shnum = u16(48);
  for (std::uint32_t i = 0; i < shnum; ++i) {
    const std::size_t sh = shoff + i * shentsize;
    if (u32(sh + 4) != 2) continue;  // SHT_SYMTAB
    const std::uint32_t sym_off = u32(sh + 16);
    const std::uint32_t sym_size = u32(sh + 20);
    const std::uint32_t strtab = u32(sh + 24);
    const std::size_t str_sh = shoff + strtab * shentsize;
    const std::uint32_t str_off = u32(str_sh + 16);
    for (std::uint32_t s = 0; s + 16 <= sym_size; s += 16) {
      const std::uint32_t name_off = u32(sym_off + s);
      const char* sym_name = data.c_str() + str_off + name_off;
      if (str_off + name_off < data.size() && name == sym_name) return u32(sym_off + s + 4);
    }
  }
  throw PilError(path + ": symbol '" + name + "' not found");
}

namespace {

/// Descriptor number of the instruction-count file inside QEMU.
constexpr int kCountsFdInQemu = 3;

/// An anonymous in-memory file: no path, nothing left behind.
int memory_file(const char* name) {
  const int fd = ::memfd_create(name, MFD_CLOEXEC);
  if (fd < 0) throw PilError(std::string("cannot create an in-memory file: ") + std::strerror(errno));
  return fd;
}

/// Everything written to `fd` so far (from offset 0; at most 16 MiB).
std::string contents(int fd) {
  std::string out;
  char buf[4096];
  for (off_t at = 0; out.size() < (std::size_t{16} << 20);) {
    const ssize_t n = ::pread(fd, buf, sizeof buf, at);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;
    out.append(buf, static_cast<std::size_t>(n));
    at += n;
  }
  return out;
}

/// A value inside a QEMU option string, where ',' separates options and ',,' is a comma.
std::string qemu_option_value(const std::string& v) {
  std::string out;
  for (char c : v) out += c == ',' ? std::string(",,") : std::string(1, c);
  return out;
}

}  // namespace

PilLink::PilLink(const PilOptions& options) : options_(options), image_(firmware_image_path(options)) {
  if (!fs::exists(image_)) {
    throw PilError(image_ + ": firmware image not found (build the host project with arm-none-eabi-gcc installed)");
  }
  const std::string machine = options.target == "cortex-m4f" ? "mps2-an386" : "microbit";
  util::ProcessSpec spec;
  spec.argv = {"qemu-system-arm", "-M",      machine, "-kernel", image_, "-display", "none",
               "-serial",         "stdio",  "-monitor", "none", "-icount", "shift=0,sleep=off"};
  stderr_fd_ = memory_file("qemu-stderr");
  if (options.count_instructions) {
    counts_fd_ = memory_file("insn-window");
    const std::string plugin = options.plugin_path.empty() ? std::string(ONESHOT_DEFAULT_QEMU_PLUGIN) : options.plugin_path;
    std::ostringstream p;
    p << qemu_option_value(plugin) << ",begin=0x" << std::hex << elf_symbol_address(image_, "oneshot_job_begin")
      << ",end=0x" << elf_symbol_address(image_, "oneshot_job_end") << std::dec
      << ",out=/proc/self/fd/" << kCountsFdInQemu;
    if (!options.profile_dir.empty()) {
      fs::create_directories(options.profile_dir);
      p << ",profile="
        << qemu_option_value((fs::absolute(options.profile_dir) / (fs::path(image_).stem().string() + ".profile")).string());
    }
    spec.argv.push_back("-plugin");
    spec.argv.push_back(p.str());
    spec.extra_fds.emplace_back(counts_fd_, kCountsFdInQemu);
  }
  int in_pipe[2] = {-1, -1};
  int out_pipe[2] = {-1, -1};
  if (::pipe2(in_pipe, O_CLOEXEC) != 0 || ::pipe2(out_pipe, O_CLOEXEC) != 0) {
    for (int fd : {in_pipe[0], in_pipe[1]})
      if (fd >= 0) ::close(fd);
    ::close(stderr_fd_);
    if (counts_fd_ >= 0) ::close(counts_fd_);
    throw PilError("cannot create pipes for QEMU");
  }
  spec.stdin_fd = in_pipe[0];
  spec.stdout_fd = out_pipe[1];
  spec.stderr_fd = stderr_fd_;
  to_qemu_ = in_pipe[1];
  from_qemu_ = out_pipe[0];
  try {
    qemu_ = std::make_unique<util::ChildProcess>(spec);
  } catch (const util::ProcessError& e) {
    ::close(in_pipe[0]);
    ::close(out_pipe[1]);
    throw PilError(std::string("cannot start QEMU (apt-get install qemu-system-arm): ") + e.what());
  }
  ::close(in_pipe[0]);
  ::close(out_pipe[1]);
  pil::Frame hello;
  if (!read_frame(hello, 10000) || static_cast<std::uint8_t>(hello.type) != 0x81) fail("no hello from the firmware");
  info_ = parse_hello(hello);
  if (info_.protocol != pil::kProtocolVersion) fail("protocol version " + std::to_string(info_.protocol) + " not supported");
}

FirmwareInfo PilLink::parse_hello(const pil::Frame& hello) {
  FirmwareInfo info;
  pil::Reader r(hello);
  info.protocol = static_cast<int>(r.u(1));
  info.target = r.u(1) == 0 ? "cortex-m0" : "cortex-m4f";
  info.format = r.u(1) == 0 ? "float" : "fixed";
  const std::uint32_t disc = r.u(1);
  info.discretizer = disc == 0 ? "table" : disc == 1 ? "generic" : "nearest";
  info.n = static_cast<int>(r.u(1));
  info.m = static_cast<int>(r.u(1));
  info.p = static_cast<int>(r.u(1));
  info.stack_peak_bytes = static_cast<int>(r.u(2));
  return info;
}

int PilLink::stack_peak_bytes() { return parse_hello(request(pil::Type::kHello, pil::Frame{})).stack_peak_bytes; }

PilLink::~PilLink() {
  if (to_qemu_ >= 0) ::close(to_qemu_);
  if (from_qemu_ >= 0) ::close(from_qemu_);
  if (qemu_) qemu_->terminate();  // SIGTERM lets the plugin write its profile; SIGKILL after 2 s
  if (stderr_fd_ >= 0) ::close(stderr_fd_);
  if (counts_fd_ >= 0) ::close(counts_fd_);
}

void PilLink::fail(const std::string& what) {
  const std::string said = stderr_fd_ >= 0 ? contents(stderr_fd_) : std::string();
  throw PilError("PIL (" + image_ + "): " + what + (said.empty() ? "" : "\nQEMU said: " + said));
}

void PilLink::write_bytes(const std::uint8_t* data, std::size_t n) {
  while (n > 0) {
    const ssize_t w = ::write(to_qemu_, data, n);
    if (w < 0 && errno == EINTR) continue;
    if (w <= 0) fail("QEMU closed its serial input");
    data += w;
    n -= static_cast<std::size_t>(w);
  }
}

bool PilLink::read_frame(pil::Frame& out, int timeout_ms) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(timeout_ms);
  std::uint8_t buf[256];
  for (;;) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now()).count();
    if (left <= 0) return false;
    pollfd p{from_qemu_, POLLIN, 0};
    const int rc = ::poll(&p, 1, static_cast<int>(left));
    if (rc < 0 && errno == EINTR) continue;
    if (rc <= 0) return false;
    const ssize_t n = ::read(from_qemu_, buf, sizeof buf);
    if (n <= 0) fail("QEMU exited");
    for (ssize_t i = 0; i < n; ++i) {
      if (decoder_.feed(buf[i])) {
        out = decoder_.frame();
        if (out.type == pil::Type::kFault) {
          pil::Reader r(out);
          const std::uint32_t line = r.u(4);
          std::string file;
          while (true) {
            const std::uint32_t c = r.u(1);
            if (r.bad()) break;
            file += static_cast<char>(c);
          }
          if (line == pil::kFaultHard) fail("firmware hard fault");
          if (line == pil::kFaultUnknownRequest) {
            fail("the firmware does not know the request type (sequence " + std::to_string(out.seq) + ")");
          }
          if (line == pil::kFaultMalformedRequest) {
            fail("the firmware refused a malformed request (sequence " + std::to_string(out.seq) +
                 "): wrong payload length or value");
          }
          fail("firmware invariant failed at " + file + ":" + std::to_string(line));
        }
        // Keep the remaining bytes for the next read: the decoder holds any partial frame.
        for (ssize_t j = i + 1; j < n; ++j) {
          if (decoder_.feed(buf[j])) pending_.push_back(decoder_.frame());
        }
        return true;
      }
    }
  }
}

pil::Frame PilLink::request(pil::Type type, const pil::Frame& payload) {
  pil::Frame q = payload;
  q.type = type;
  q.seq = seq_++;
  std::uint8_t wire[2 * (pil::kMaxPayload + 5) + 2];
  const std::size_t n = pil::encode(q, wire);
  if (options_.fault_every > 0 && q.seq % options_.fault_every == 0) {
    static constexpr LinkFault kCycle[] = {LinkFault::kCorruptByte, LinkFault::kDropByte, LinkFault::kLoseReply};
    fault_ = kCycle[(q.seq / options_.fault_every) % 3];
  }
  for (int attempt = 0; attempt <= options_.retries; ++attempt) {
    if (attempt > 0) ++resends_;
    if (fault_ == LinkFault::kCorruptByte) {
      std::uint8_t bad[sizeof wire];
      std::memcpy(bad, wire, n);
      bad[n / 2] ^= 0x10U;
      write_bytes(bad, n);
      fault_ = LinkFault::kNone;
    } else if (fault_ == LinkFault::kDropByte) {
      write_bytes(wire, n / 2);
      write_bytes(wire + n / 2 + 1, n - n / 2 - 1);
      fault_ = LinkFault::kNone;
    } else {
      write_bytes(wire, n);
    }
    pil::Frame r;
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(options_.timeout_ms);
    while (std::chrono::steady_clock::now() < deadline) {
      const int left = static_cast<int>(
          std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now()).count());
      bool got = false;
      if (!pending_.empty()) {
        r = pending_.front();
        pending_.erase(pending_.begin());
        got = true;
      } else {
        got = read_frame(r, std::max(1, left));
      }
      if (!got) break;
      if (r.seq == q.seq && static_cast<std::uint8_t>(r.type) == (static_cast<std::uint8_t>(type) | 0x80U)) {
        if (fault_ != LinkFault::kLoseReply) return r;
        fault_ = LinkFault::kNone;  // pretend it never arrived: time out and resend
        continue;
      }
      // A stale reply (to an earlier resend): ignore it.
    }
  }
  fail("no reply to request type " + std::to_string(static_cast<int>(type)) + " after " +
       std::to_string(options_.retries + 1) + " attempts");
}

std::vector<std::uint64_t> PilLink::instruction_counts() const {
  std::vector<std::uint64_t> counts;
  if (counts_fd_ < 0) return counts;
  std::istringstream in(contents(counts_fd_));
  std::uint64_t v = 0;
  while (in >> v) counts.push_back(v);
  return counts;
}

}  // namespace oneshot::sim
