/// @file pil_link.hpp
/// @brief The host end of the processor-in-the-loop link: QEMU running a firmware image,
///        framed requests over its UART, instruction counts from the insn_window plugin.
#pragma once

#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "oneshot/app/pil_protocol.hpp"

namespace oneshot::util {
class ChildProcess;
}  // namespace oneshot::util

namespace oneshot::sim {

/// The link or the firmware failed (no QEMU, no image, timeout, firmware fault).
class PilError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Where to find things.
struct PilOptions {
  std::string target = "cortex-m0";  ///< cortex-m0 (QEMU microbit) or cortex-m4f (mps2-an386).
  std::string format = "float";      ///< float or fixed.
  std::string discretizer = "table"; ///< table or generic.
  std::string firmware_dir;          ///< Build tree holding firmware-<target>/ (default: this build's).
  std::string image_name;            ///< Image file under firmware-<target>/ (empty: by format and discretizer).
  bool count_instructions = false;   ///< Load the insn_window plugin.
  std::string plugin_path;           ///< The plugin (default: this build's).
  std::string profile_dir;           ///< With count_instructions: write <image>.profile here
                                     ///< (executions per instruction address inside the jobs).
  int timeout_ms = 2000;             ///< Per reply.
  int retries = 5;                   ///< Resends of one request.
  int fault_every = 0;               ///< Link test: damage every n-th request (0: never), cycling
                                     ///< through the faults of LinkFault.
};

/// What the firmware reports in kHello.
struct FirmwareInfo {
  int protocol = 0;        ///< Protocol version.
  std::string target;      ///< cortex-m0 / cortex-m4f.
  std::string format;      ///< float / fixed.
  std::string discretizer; ///< table / generic.
  int n = 0, m = 0, p = 0; ///< Dimensions.
  int stack_peak_bytes = 0; ///< Deepest stack use since reset when the kHello was sent.
};

/// Path of the image for `options` (firmware_dir/firmware-<target>/oneshot-<target>-<format>-<disc>.elf,
/// or image_name in that folder).
std::string firmware_image_path(const PilOptions& options);

/// Largest firmware image read (ELF with debug information): 64 MiB.
inline constexpr std::size_t kMaxImageBytes = std::size_t{64} << 20;

/// Address of symbol `name` in a 32-bit little-endian ELF file (PilError when absent).
std::uint32_t elf_symbol_address(const std::string& elf_path, const std::string& name);

/// Flash (text + rodata + initialised data) and static RAM (data + bss) of an ELF image, bytes.
std::pair<std::size_t, std::size_t> image_memory(const std::string& elf_path);

/// Link faults for tests: corrupt or drop one byte of the next request, or lose its reply
/// (the firmware has run the job: the resend must not run it again).
enum class LinkFault { kNone, kCorruptByte, kDropByte, kLoseReply };

/// A running firmware image behind its UART. QEMU runs in its own process group, without a
/// shell, and dies with the thread that created the link (PR_SET_PDEATHSIG) or with the
/// termination handlers; its error output and the instruction counts go to in-memory
/// files, so nothing is left on disk even when the harness is killed.
class PilLink {
 public:
  /// Starts QEMU with the image of `options` and waits for its kHello.
  explicit PilLink(const PilOptions& options);
  ~PilLink();
  PilLink(const PilLink&) = delete;
  PilLink& operator=(const PilLink&) = delete;

  /// The image's self-description at boot.
  const FirmwareInfo& info() const { return info_; }
  /// Deepest stack use of the firmware so far (asks it: one kHello round trip).
  int stack_peak_bytes();
  /// Sends a request and returns the reply, resending on timeout (PilError when exhausted).
  app::pil::Frame request(app::pil::Type type, const app::pil::Frame& payload);
  /// Requests resent so far (timeouts and corrupted frames).
  std::uint32_t resends() const { return resends_; }
  /// Damages the next request once (tests of resynchronisation).
  void inject(LinkFault fault) { fault_ = fault; }
  /// Instructions counted between the markers so far, in execution order.
  std::vector<std::uint64_t> instruction_counts() const;
  /// The image in use.
  const std::string& image() const { return image_; }

 private:
  bool read_frame(app::pil::Frame& out, int timeout_ms);
  void write_bytes(const std::uint8_t* data, std::size_t n);
  [[noreturn]] void fail(const std::string& what);

  PilOptions options_;
  std::string image_;
  std::unique_ptr<util::ChildProcess> qemu_;  // own process group, ended with us
  int stderr_fd_ = -1;   // QEMU's standard error: an in-memory file (no temporary folder)
  int counts_fd_ = -1;   // the plugin's instruction counts: an in-memory file
  int to_qemu_ = -1;
  int from_qemu_ = -1;
  static FirmwareInfo parse_hello(const app::pil::Frame& hello);

  app::pil::Decoder decoder_;
  std::vector<app::pil::Frame> pending_;  // frames decoded after the one returned
  std::uint16_t seq_ = 1;
  std::uint32_t resends_ = 0;
  LinkFault fault_ = LinkFault::kNone;
  FirmwareInfo info_;
};

}  // namespace oneshot::sim
