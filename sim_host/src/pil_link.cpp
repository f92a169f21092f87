/// @file pil_link.cpp
/// @brief QEMU process, framing and retries (see pil_link.hpp).
#include "oneshot/sim/pil_link.hpp"

#include <cerrno>
#include <fcntl.h>
#include <chrono>
#include <csignal>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <poll.h>
#include <spawn.h>
#include <sstream>
#include <sys/wait.h>
#include <unistd.h>

extern char** environ;

namespace oneshot::sim {

namespace fs = std::filesystem;
namespace pil = app::pil;

std::string firmware_image_path(const PilOptions& o) {
  const std::string dir = o.firmware_dir.empty() ? std::string(ONESHOT_DEFAULT_FIRMWARE_DIR) : o.firmware_dir;
  return (fs::path(dir) / ("firmware-" + o.target) / ("oneshot-" + o.target + "-" + o.format + "-" + o.discretizer + ".elf"))
      .string();
}

std::uint32_t elf_symbol_address(const std::string& path, const std::string& name) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw PilError(path + ": cannot read the firmware image");
  const std::string data((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
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

PilLink::PilLink(const PilOptions& options) : options_(options), image_(firmware_image_path(options)) {
  if (!fs::exists(image_)) {
    throw PilError(image_ + ": firmware image not found (build the host project with arm-none-eabi-gcc installed)");
  }
  static int counter = 0;
  workdir_ = (fs::temp_directory_path() / ("oneshot_pil_" + std::to_string(::getpid()) + "_" + std::to_string(counter++))).string();
  fs::create_directories(workdir_);
  const std::string machine = options.target == "cortex-m4f" ? "mps2-an386" : "microbit";
  std::vector<std::string> args = {"qemu-system-arm", "-M",      machine, "-kernel", image_, "-display", "none",
                                   "-serial",         "stdio",  "-monitor", "none", "-icount", "shift=0,sleep=off"};
  if (options.count_instructions) {
    const std::string plugin = options.plugin_path.empty() ? std::string(ONESHOT_DEFAULT_QEMU_PLUGIN) : options.plugin_path;
    counts_path_ = (fs::path(workdir_) / "instructions.txt").string();
    std::ostringstream p;
    p << plugin << ",begin=0x" << std::hex << elf_symbol_address(image_, "oneshot_job_begin") << ",end=0x"
      << elf_symbol_address(image_, "oneshot_job_end") << ",out=" << counts_path_;
    if (!options.profile_dir.empty()) {
      fs::create_directories(options.profile_dir);
      p << ",profile=" << (fs::absolute(options.profile_dir) / (fs::path(image_).stem().string() + ".profile")).string();
    }
    args.push_back("-plugin");
    args.push_back(p.str());
  }
  int in_pipe[2];
  int out_pipe[2];
  if (::pipe(in_pipe) != 0 || ::pipe(out_pipe) != 0) throw PilError("cannot create pipes for QEMU");
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, in_pipe[0], STDIN_FILENO);
  posix_spawn_file_actions_adddup2(&actions, out_pipe[1], STDOUT_FILENO);
  const std::string err_path = (fs::path(workdir_) / "qemu.stderr").string();
  posix_spawn_file_actions_addopen(&actions, STDERR_FILENO, err_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_addclose(&actions, in_pipe[1]);
  posix_spawn_file_actions_addclose(&actions, out_pipe[0]);
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  pid_t pid = 0;
  const int rc = posix_spawnp(&pid, "qemu-system-arm", &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  ::close(in_pipe[0]);
  ::close(out_pipe[1]);
  to_qemu_ = in_pipe[1];
  from_qemu_ = out_pipe[0];
  if (rc != 0) {
    ::close(to_qemu_);
    ::close(from_qemu_);
    throw PilError("cannot start qemu-system-arm (apt-get install qemu-system-arm): " + std::string(std::strerror(rc)));
  }
  pid_ = pid;
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
  if (pid_ > 0) {
    ::kill(pid_, SIGTERM);
    int status = 0;
    ::waitpid(pid_, &status, 0);
  }
  std::error_code ec;
  fs::remove_all(workdir_, ec);
}

void PilLink::fail(const std::string& what) {
  std::ifstream err((fs::path(workdir_) / "qemu.stderr").string());
  std::ostringstream s;
  s << err.rdbuf();
  throw PilError("PIL (" + image_ + "): " + what + (s.str().empty() ? "" : "\nQEMU said: " + s.str()));
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
          fail(line == 0xFFFFFFFFU ? "firmware hard fault" : "firmware invariant failed at " + file + ":" + std::to_string(line));
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
  std::ifstream in(counts_path_);
  std::uint64_t v = 0;
  while (in >> v) counts.push_back(v);
  return counts;
}

}  // namespace oneshot::sim
